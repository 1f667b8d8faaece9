beta = 65;
joint = 1;
Include "specimen.geo";
