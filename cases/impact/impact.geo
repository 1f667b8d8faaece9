// A disc of radius 0.1 m just above a fixed base (seed paper, Section 3.2, Fig. 11).
Geometry.AutoCoherence = 0;
If(!Exists(size)) size = 0.01; EndIf
If(!Exists(gap)) gap = 1e-3; EndIf
r = 0.1;
Point(1) = {-0.2, -0.05, 0, 2 * size};
Point(2) = {0.2, -0.05, 0, 2 * size};
Point(3) = {0.2, 0, 0, size};
Point(4) = {-0.2, 0, 0, size};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Point(10) = {0, r + gap, 0, size};
Point(11) = {r, r + gap, 0, size};
Point(12) = {0, 2 * r + gap, 0, size};
Point(13) = {-r, r + gap, 0, size};
Point(14) = {0, gap, 0, size};
Circle(11) = {11, 10, 12}; Circle(12) = {12, 10, 13}; Circle(13) = {13, 10, 14}; Circle(14) = {14, 10, 11};
Curve Loop(2) = {11, 12, 13, 14};
Plane Surface(2) = {2};
Physical Surface("base") = {1};
Physical Surface("disc") = {2};
