joint = 0;
Include "specimen.geo";
