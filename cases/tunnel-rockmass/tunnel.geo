// A square plate of rock, 12 m x 12 m, with a circular tunnel of radius a = 1 m at its
// centre and three joints at 30° from x, for cases/tunnel-rockmass. The tunnel's disc is
// its own physical surface ("tunnel"), meshed and fracturable like the rock, so that it is
// there at the start and [[excavation]] removes it with the CE4s inside it and on the
// wall. The joints are curves of the mesh (docs/case-format.md, [[joint]], curves): the
// line u = (cos 30°, sin 30°) at the offset d along n = (-sin 30°, cos 30°) from the
// centre, for d = 0.5 m (it crosses the tunnel: it meets the wall at 60° and at 180°, where
// the circle is split), d = -2 m and d = 2.5 m (in the rock only, ending inside the plate).
// Mesh with: gmsh -2 tunnel.geo -setnumber size 1 (the case's mesh.size scales every
// element size).
If(!Exists(size)) size = 1.0; EndIf
wall = 0.15 * size;   // element size at the tunnel wall [m]
far = 1.0 * size;     // element size at the plate's edges [m]
mid = 0.3 * size;     // element size at the joints' ends in the rock [m]
a = 1.0;
L = 6.0;              // half the plate's side
c = Cos(Pi / 6);
s = Sin(Pi / 6);
Point(1) = {0, 0, 0, 0.4 * size};   // the centre
Point(2) = {a, 0, 0, wall};
Point(3) = {0, a, 0, wall};
Point(4) = {-a, 0, 0, wall};        // joint 1 meets the wall here (180°)
Point(5) = {0, -a, 0, wall};
Point(10) = {a * Cos(Pi / 3), a * Sin(Pi / 3), 0, wall};   // and here (60°)
Point(6) = {-L, -L, 0, far};
Point(7) = {L, -L, 0, far};
Point(8) = {L, L, 0, far};
Point(9) = {-L, L, 0, far};
Circle(1) = {2, 1, 10};
Circle(11) = {10, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 2};
Line(5) = {6, 7};   // y = -L
Line(6) = {7, 8};   // x = L
Line(7) = {8, 9};   // y = L
Line(8) = {9, 6};   // x = -L
Curve Loop(1) = {5, 6, 7, 8};
Curve Loop(2) = {1, 11, 2, 3, 4};
Plane Surface(1) = {1, 2};
Plane Surface(2) = {2};

// Joint 1, d = 0.5: base point d n, the wall at s = ±√(a² − d²) along u, ends at s = ±4.5.
d1 = 0.5;
Point(20) = {-d1 * s + 4.5 * c, d1 * c + 4.5 * s, 0, mid};
Point(21) = {-d1 * s - 4.5 * c, d1 * c - 4.5 * s, 0, mid};
Line(20) = {10, 20};   // in the rock
Line(21) = {4, 21};    // in the rock
Line(22) = {4, 10};    // across the tunnel
// Joint 2, d = -2, s from -4.5 to 4.5; joint 3, d = 2.5, s from -4 to 4.
d2 = -2.0;
Point(22) = {-d2 * s - 4.5 * c, d2 * c - 4.5 * s, 0, mid};
Point(23) = {-d2 * s + 4.5 * c, d2 * c + 4.5 * s, 0, mid};
Line(23) = {22, 23};
d3 = 2.5;
Point(24) = {-d3 * s - 4.0 * c, d3 * c - 4.0 * s, 0, mid};
Point(25) = {-d3 * s + 4.0 * c, d3 * c + 4.0 * s, 0, mid};
Line(24) = {24, 25};
Line{20, 21, 23, 24} In Surface{1};
Line{22} In Surface{2};

Physical Surface("rock") = {1};
Physical Surface("tunnel") = {2};
Physical Curve("bottom") = {5};
Physical Curve("right") = {6};
Physical Curve("top") = {7};
Physical Curve("left") = {8};
Physical Curve("wall") = {1, 11, 2, 3, 4};
Physical Curve("joint1") = {20, 21, 22};
Physical Curve("joint2") = {23};
Physical Curve("joint3") = {24};
