beta = 50;
joint = 1;
Include "specimen.geo";
