// A blast hole (radius 0.05 m) in a rock disc (radius 5 m), the paper's Fig. 17.
// Element size grows linearly with the distance from the hole centre: `size` at the
// hole, growing by `grade` per metre (by default 1.833 × size, so that `size` alone
// scales the whole mesh; size 0.012 m gives about 46k TRI3, 0.4 m at the rim).
// Embedded points at r = 1, 2, 3, 4 m on the x and y axes are the wave stations
// (Physical Points x1..x4, y1..y4) whose history gives the apparent P-wave speed.
If(!Exists(size)) size = 0.012; EndIf
If(!Exists(grade)) grade = 1.8333 * size; EndIf
R = 5.0;
r = 0.05;
Point(1) = {0, 0, 0};
Point(2) = {R, 0, 0}; Point(3) = {0, R, 0}; Point(4) = {-R, 0, 0}; Point(5) = {0, -R, 0};
Point(6) = {r, 0, 0}; Point(7) = {0, r, 0}; Point(8) = {-r, 0, 0}; Point(9) = {0, -r, 0};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4}; Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 2};
Circle(5) = {6, 1, 7}; Circle(6) = {7, 1, 8}; Circle(7) = {8, 1, 9}; Circle(8) = {9, 1, 6};
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};
For k In {1:4}
  Point(10 + k) = {k, 0, 0};
  Point(20 + k) = {0, k, 0};
EndFor
Point{11, 12, 13, 14, 21, 22, 23, 24} In Surface{1};
Field[1] = MathEval;
Field[1].F = Sprintf("%g + %g * (Sqrt(x*x + y*y) - 0.05)", size, grade);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Physical Surface("rock") = {1};
Physical Curve("outer") = {1, 2, 3, 4};
Physical Curve("hole") = {5, 6, 7, 8};
For k In {1:4}
  Physical Point(Sprintf("x%g", k)) = {10 + k};
  Physical Point(Sprintf("y%g", k)) = {20 + k};
EndFor
