beta = 75;
joint = 1;
Include "specimen.geo";
