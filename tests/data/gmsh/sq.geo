// Unit square split at x = 0.5 into two physical surfaces; fixture for the Gmsh reader tests.
// All four file forms are generated from it:
//   gmsh -2 sq.geo -format msh22 -o sq22a.msh      gmsh -2 sq.geo -format msh22 -bin -o sq22b.msh
//   gmsh -2 sq.geo -format msh41 -o sq41a.msh      gmsh -2 sq.geo -format msh41 -bin -o sq41b.msh
// sq22b_be.msh is sq22b.msh with every binary value byte-swapped (make_big_endian.py).
DefineConstant[ size = 0.4 ];
Point(1) = {0, 0, 0, size};
Point(2) = {0.5, 0, 0, size};
Point(3) = {1, 0, 0, size};
Point(4) = {1, 1, 0, size};
Point(5) = {0.5, 1, 0, size};
Point(6) = {0, 1, 0, size};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Line(7) = {2, 5};
Curve Loop(1) = {1, 7, 5, 6};
Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, 4, -7};
Plane Surface(2) = {2};
Physical Surface("left_half") = {1};
Physical Surface("right_half") = {2};
Physical Curve("bottom") = {1, 2};
Physical Curve("top") = {4, 5};
Physical Point("origin") = {1};
