// A long elastic strip, 3 m × 0.05 m, made of six blocks of 0.5 m: the vertical lines
// between them at x = 0.5 … 2.5 m are the stations (Physical Curves s1 … s5) whose mean
// displacement in the history gives the arrival of the wave front.
If(!Exists(size)) size = 0.01; EndIf
H = 0.05;
For k In {0:6}
  Point(1 + k) = {0.5 * k, 0, 0, size};    // bottom
  Point(11 + k) = {0.5 * k, H, 0, size};   // top
  Line(21 + k) = {1 + k, 11 + k};          // vertical at x = 0.5 k
EndFor
For k In {0:5}
  Line(31 + k) = {1 + k, 2 + k};           // bottom
  Line(41 + k) = {12 + k, 11 + k};         // top, right to left
  Curve Loop(51 + k) = {31 + k, 22 + k, 41 + k, -(21 + k)};
  Plane Surface(51 + k) = {51 + k};
EndFor
Physical Surface("bar") = {51:56};
Physical Curve("left") = {21};
Physical Curve("right") = {27};
Physical Curve("sides") = {31:36, 41:46};
For k In {1:5}
  Physical Curve(Sprintf("s%g", k)) = {21 + k};
EndFor
