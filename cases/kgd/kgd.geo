// KGD: a plane-strain fracture driven from the well (the origin) along y = 0, the one
// line of weak CE4s (the [[interface]] between the materials "upper" and "lower"; each
// half's own CE4s are strong, so the crack stays on the line). A square plate of half
// width `half`; the edges along y = 0 are `size` (mesh.size) long within |x| < `fine`,
// the mesh grows to `outer` at the plate's edge. The seed crack ("seed", the CE4s that
// start broken) is `seed` edges on each side of the well, and at least 0.25 m.
If(!Exists(size)) size = 0.05; EndIf
half = 6.0;
outer = 0.75;
fine = 2.0;
seed = 5;
s = Max(0.25, seed * size);  // at least 0.25 m: finer meshes keep the seed's length, not its count
Point(1) = {-half, 0, 0, outer}; Point(2) = {-fine, 0, 0, size}; Point(3) = {-s, 0, 0, size};
Point(4) = {0, 0, 0, size}; Point(5) = {s, 0, 0, size}; Point(6) = {fine, 0, 0, size};
Point(7) = {half, 0, 0, outer};
Point(8) = {half, half, 0, outer}; Point(9) = {-half, half, 0, outer};
Point(10) = {-half, -half, 0, outer}; Point(11) = {half, -half, 0, outer};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6}; Line(6) = {6, 7};
Line(7) = {7, 8}; Line(8) = {8, 9}; Line(9) = {9, 1};
Line(10) = {1, 10}; Line(11) = {10, 11}; Line(12) = {11, 7};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8, 9};
Plane Surface(1) = {1};
Curve Loop(2) = {-6, -5, -4, -3, -2, -1, 10, 11, 12};
Plane Surface(2) = {2};
// Size: `size` within 3 edges of the fine part of the line, growing to `outer` 4 m away.
Field[1] = Distance;
Field[1].CurvesList = {2, 3, 4, 5};
Field[1].NumPointsPerCurve = 400;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = size;
Field[2].SizeMax = outer;
Field[2].DistMin = 3 * size;
Field[2].DistMax = 4.0;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Physical Surface("upper") = {1};
Physical Surface("lower") = {2};
Physical Curve("seed") = {3, 4};
Physical Curve("outside") = {7, 8, 9, 10, 11, 12};
Physical Point("well") = {4};
