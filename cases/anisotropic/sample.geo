// A 0.4 m x 0.2 m sample for the anisotropic uniaxial stretch (case.toml).
If(!Exists(size)) size = 0.05; EndIf
Point(1) = {0, 0, 0, size};
Point(2) = {0.4, 0, 0, size};
Point(3) = {0.4, 0.2, 0, size};
Point(4) = {0, 0.2, 0, size};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("sample") = {1};
Physical Curve("left") = {4};
Physical Curve("right") = {2};
Physical Point("corner") = {1};
