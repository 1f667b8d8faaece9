// A 40 mm x 40 mm square cut into [grains] (tests/test_grains.cpp), on a 40 x 10 mm
// steel strip (a second surface outside the grains' region).
If(!Exists(size)) size = 1.0e-3; EndIf
Point(1) = {0, 0, 0, size};
Point(2) = {0.04, 0, 0, size};
Point(3) = {0.04, 0.04, 0, size};
Point(4) = {0, 0.04, 0, size};
Point(5) = {0, -0.01, 0, size};
Point(6) = {0.04, -0.01, 0, size};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {5, 6};
Line(6) = {6, 2};
Line(7) = {1, 5};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, -1, 7};
Plane Surface(2) = {2};
Physical Surface("rock") = {1};
Physical Surface("base") = {2};
Physical Curve("top") = {3};
Physical Curve("bottom") = {5};
