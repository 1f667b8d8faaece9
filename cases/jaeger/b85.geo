beta = 85;
joint = 1;
Include "specimen.geo";
