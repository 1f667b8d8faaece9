// Sneddon's pressurised crack: a straight crack of length 2a (a = 1 m) along y = 0 in
// the middle of a 40 m x 40 m plate. The crack lies inside a thin fracturable strip
// (two rows of triangles above and below y = 0) whose CE4s on the physical curve
// "crack" start broken ([fluid] crack); the rest of the plate is not fracturable.
// `size` (mesh.size): the edge length along the crack, 2a / size edges (0.05: 40); the
// mesh grows to 1 m at the plate's edge.
If(!Exists(size)) size = 0.05; EndIf
outer = 2.0;
half = 20.0;
a = 1.0;
h = size;
w = 1.5 * a;     // half-length of the strip
t = 2 * h;       // strip: two rows of triangles on each side
Point(1) = {-w, 0, 0, h}; Point(2) = {-a, 0, 0, h}; Point(3) = {0, 0, 0, h};
Point(4) = {a, 0, 0, h}; Point(5) = {w, 0, 0, h};
Point(6) = {w, t, 0, h}; Point(7) = {-w, t, 0, h};
Point(8) = {w, -t, 0, h}; Point(9) = {-w, -t, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 1};
Line(8) = {5, 8}; Line(9) = {8, 9}; Line(10) = {9, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7};
Plane Surface(1) = {1};
Curve Loop(2) = {-4, -3, -2, -1, -10, -9, -8};
Plane Surface(2) = {2};
Point(10) = {-half, -half, 0, outer}; Point(11) = {half, -half, 0, outer};
Point(12) = {half, half, 0, outer}; Point(13) = {-half, half, 0, outer};
Line(11) = {10, 11}; Line(12) = {11, 12}; Line(13) = {12, 13}; Line(14) = {13, 10};
Curve Loop(3) = {11, 12, 13, 14};
Curve Loop(4) = {5, 6, 7, -10, -9, -8};
Plane Surface(3) = {3, 4};
Physical Surface("strip") = {1, 2};
Physical Surface("plate") = {3};
Physical Curve("crack") = {2, 3};
Physical Curve("outside") = {11, 12, 13, 14};
Physical Point("well") = {3};
