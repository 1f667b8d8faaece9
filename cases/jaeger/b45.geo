beta = 45;
joint = 1;
Include "specimen.geo";
