beta = 80;
joint = 1;
Include "specimen.geo";
