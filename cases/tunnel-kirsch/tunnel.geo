// A quarter of a square plate, 20 m x 20 m, with a circular tunnel of radius a = 1 m at
// the corner (x = y = 0: the symmetry lines), for cases/tunnel-kirsch. The tunnel's
// quarter disc is its own physical surface ("tunnel"), meshed with the rock, so that it
// is there at the start and [[excavation]] removes it.
// Mesh with: gmsh -2 tunnel.geo -setnumber size 1 (the case's mesh.size: a scale on
// both element sizes; tests/data/cases/tunnel_small.msh is size 4, -format msh22).
If(!Exists(size)) size = 1.0; EndIf
wall = 0.02 * size;   // element size at the tunnel wall [m]
far = 1.6 * size;     // element size at the plate's outer edges [m]
a = 1.0;
L = 20.0;
Point(1) = {0, 0, 0, 0.25 * size};   // the centre: the core goes, its mesh need not be fine
Point(2) = {a, 0, 0, wall};
Point(3) = {L, 0, 0, far};
Point(4) = {L, L, 0, far};
Point(5) = {0, L, 0, far};
Point(6) = {0, a, 0, wall};
Line(1) = {2, 3};           // y = 0, rock
Line(2) = {3, 4};           // x = L
Line(3) = {4, 5};           // y = L
Line(4) = {5, 6};           // x = 0, rock
Circle(5) = {6, 1, 2};      // the wall
Line(6) = {1, 2};           // y = 0, tunnel
Line(7) = {6, 1};           // x = 0, tunnel
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
Curve Loop(2) = {6, -5, 7};
Plane Surface(2) = {2};
Physical Surface("rock") = {1};
Physical Surface("tunnel") = {2};
Physical Curve("bottom") = {1, 6};   // y = 0: symmetry, rollers in y
Physical Curve("left") = {4, 7};     // x = 0: symmetry, rollers in x
Physical Curve("right") = {2};
Physical Curve("top") = {3};
