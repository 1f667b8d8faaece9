// Jaeger's single plane of weakness: a W x H specimen (mm; the case's mesh.scale = 1e-3)
// centred on the origin, sigma_1 along y. With joint = 1 a straight joint runs through
// the centre, its normal at beta degrees from the y axis (so the joint itself at beta
// from the x axis), from side to side or, when steeper than the diagonal, from the
// bottom to the top; it splits the specimen into two surfaces and is the physical curve
// "joint". With joint = 0 the same rectangle is one surface (the intact specimen).
// The angle files (b35.geo, ..., intact.geo) set beta and joint and include this one.
DefineConstant[ size = 4 ];        // element size [mm] (the case's mesh.size)
DefineConstant[ beta = 45 ];       // angle between the joint's normal and sigma_1 [deg]
DefineConstant[ joint = 1 ];
W = 50; H = 100;
Point(1) = {-W/2, -H/2, 0, size};
Point(2) = { W/2, -H/2, 0, size};
Point(3) = { W/2,  H/2, 0, size};
Point(4) = {-W/2,  H/2, 0, size};
If (joint == 0)
  Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
  Curve Loop(1) = {1, 2, 3, 4};
  Plane Surface(1) = {1};
  Physical Curve("bottom") = {1};
  Physical Curve("right") = {2};
  Physical Curve("top") = {3};
  Physical Curve("left") = {4};
  Physical Surface("rock") = {1};
Else
  t = Tan(beta * Pi / 180);
  If (t * W / 2 < H / 2)            // from the left side to the right side
    Point(5) = {-W/2, -t * W/2, 0, size};
    Point(6) = { W/2,  t * W/2, 0, size};
    Line(1) = {1, 2};  Line(2) = {2, 6};  Line(3) = {6, 3};  Line(4) = {3, 4};
    Line(5) = {4, 5};  Line(6) = {5, 1};  Line(7) = {5, 6};
    Curve Loop(1) = {1, 2, -7, 6};
    Curve Loop(2) = {7, 3, 4, 5};
    Physical Curve("bottom") = {1};
    Physical Curve("right") = {2, 3};
    Physical Curve("top") = {4};
    Physical Curve("left") = {5, 6};
  Else                              // from the bottom to the top
    Point(5) = {-H / (2 * t), -H/2, 0, size};
    Point(6) = { H / (2 * t),  H/2, 0, size};
    Line(1) = {1, 5};  Line(2) = {5, 2};  Line(3) = {2, 3};  Line(4) = {3, 6};
    Line(5) = {6, 4};  Line(6) = {4, 1};  Line(7) = {5, 6};
    Curve Loop(1) = {1, 7, 5, 6};
    Curve Loop(2) = {2, 3, 4, -7};
    Physical Curve("bottom") = {1, 2};
    Physical Curve("right") = {3};
    Physical Curve("top") = {4, 5};
    Physical Curve("left") = {6};
  EndIf
  Plane Surface(1) = {1};
  Plane Surface(2) = {2};
  Physical Curve("joint") = {7};
  Physical Surface("rock") = {1, 2};
EndIf
Physical Point("pin") = {1};
Mesh.Algorithm = 5;                 // Delaunay: edge directions spread evenly (docs/case-format.md)
