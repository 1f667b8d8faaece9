Geometry.AutoCoherence = 0;
If(!Exists(size)) size = 0.6e-3; EndIf
W = 0.0517; H = 0.1295;
Point(1) = {-W/2, -H/2, 0, size}; Point(2) = {W/2, -H/2, 0, size}; Point(3) = {W/2, H/2, 0, size}; Point(4) = {-W/2, H/2, 0, size};
Line(1) = {1,2}; Line(2) = {2,3}; Line(3) = {3,4}; Line(4) = {4,1};
Curve Loop(1) = {1,2,3,4}; Plane Surface(1) = {1};
ps = 4*size;
Point(11) = {-0.035, H/2, 0, ps}; Point(12) = {0.035, H/2, 0, ps}; Point(13) = {0.035, H/2+0.005, 0, ps}; Point(14) = {-0.035, H/2+0.005, 0, ps};
Line(11) = {11,12}; Line(12) = {12,13}; Line(13) = {13,14}; Line(14) = {14,11};
Curve Loop(2) = {11,12,13,14}; Plane Surface(2) = {2};
Point(21) = {-0.035, -H/2-0.005, 0, ps}; Point(22) = {0.035, -H/2-0.005, 0, ps}; Point(23) = {0.035, -H/2, 0, ps}; Point(24) = {-0.035, -H/2, 0, ps};
Line(21) = {21,22}; Line(22) = {22,23}; Line(23) = {23,24}; Line(24) = {24,21};
Curve Loop(3) = {21,22,23,24}; Plane Surface(3) = {3};
Physical Surface("rock") = {1};
Physical Surface("platen_top") = {2};
Physical Surface("platen_bottom") = {3};
Physical Curve("rim") = {1,2,3,4};
