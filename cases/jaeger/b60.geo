beta = 60;
joint = 1;
Include "specimen.geo";
