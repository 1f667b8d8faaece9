// Three 10 cm x 5 cm blocks stacked on a fixed base.
Geometry.AutoCoherence = 0;
If(!Exists(size)) size = 0.01; EndIf
Point(1) = {-0.15, -0.02, 0, size}; Point(2) = {0.15, -0.02, 0, size};
Point(3) = {0.15, 0, 0, size}; Point(4) = {-0.15, 0, 0, size};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
For k In {1:3}
  y0 = 0.05 * (k - 1);
  p = newp;
  Point(p) = {-0.05, y0, 0, size}; Point(p + 1) = {0.05, y0, 0, size};
  Point(p + 2) = {0.05, y0 + 0.05, 0, size}; Point(p + 3) = {-0.05, y0 + 0.05, 0, size};
  l = newl;
  Line(l) = {p, p + 1}; Line(l + 1) = {p + 1, p + 2}; Line(l + 2) = {p + 2, p + 3}; Line(l + 3) = {p + 3, p};
  c = newll;
  Curve Loop(c) = {l, l + 1, l + 2, l + 3};
  s = news;
  Plane Surface(s) = {c};
  Physical Surface(Sprintf("block%g", k)) = {s};
  Physical Curve(Sprintf("block%g_bottom", k)) = {l};
  Physical Curve(Sprintf("block%g_top", k)) = {l + 2};
EndFor
Physical Surface("base") = {1};
Physical Curve("base_top") = {3};
