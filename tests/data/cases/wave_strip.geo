// A 2 m x 0.1 m strip for wave-propagation tests (tests/data/cases/wave_strip.toml).
If(!Exists(size)) size = 0.02; EndIf
Point(1) = {0, 0, 0, size};
Point(2) = {2, 0, 0, size};
Point(3) = {2, 0.1, 0, size};
Point(4) = {0, 0.1, 0, size};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("strip") = {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
