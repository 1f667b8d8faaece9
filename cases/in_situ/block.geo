// A 20 m x 20 m block of a vertical section, 500 m to 520 m below the ground surface
// (y = 0), for cases/in_situ. Mesh with: gmsh -2 block.geo -setnumber size 1.0
If(!Exists(size)) size = 1.0; EndIf
Point(1) = {0, -520, 0, size};
Point(2) = {20, -520, 0, size};
Point(3) = {20, -500, 0, size};
Point(4) = {0, -500, 0, size};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("rock") = {1};
Physical Curve("base") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
