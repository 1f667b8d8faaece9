beta = 40;
joint = 1;
Include "specimen.geo";
