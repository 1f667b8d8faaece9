// Geostatic column of the seed paper's Section 3.1: 50 m wide, 100 m tall.
// Mesh with: gmsh -2 column.geo -setnumber size 0.345
If(!Exists(size)) size = 0.345; EndIf
Point(1) = {0, 0, 0, size};
Point(2) = {50, 0, 0, size};
Point(3) = {50, 100, 0, size};
Point(4) = {0, 100, 0, size};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("rock") = {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
