beta = 70;
joint = 1;
Include "specimen.geo";
