beta = 35;
joint = 1;
Include "specimen.geo";
