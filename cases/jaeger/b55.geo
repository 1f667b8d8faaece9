beta = 55;
joint = 1;
Include "specimen.geo";
