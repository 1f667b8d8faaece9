Geometry.AutoCoherence = 0;
If(!Exists(size)) size = 0.7e-3; EndIf
R = 0.0517/2;
Point(1) = {0,0,0,size}; Point(2) = {R,0,0,size}; Point(3) = {0,R,0,size}; Point(4) = {-R,0,0,size}; Point(5) = {0,-R,0,size};
Circle(1) = {2,1,3}; Circle(2) = {3,1,4}; Circle(3) = {4,1,5}; Circle(4) = {5,1,2};
Curve Loop(1) = {1,2,3,4}; Plane Surface(1) = {1};
ps = 4*size;
Point(11) = {-0.03, R, 0, ps}; Point(12) = {0.03, R, 0, ps}; Point(13) = {0.03, R+0.005, 0, ps}; Point(14) = {-0.03, R+0.005, 0, ps};
Line(11) = {11,12}; Line(12) = {12,13}; Line(13) = {13,14}; Line(14) = {14,11};
Curve Loop(2) = {11,12,13,14}; Plane Surface(2) = {2};
Point(21) = {-0.03, -R-0.005, 0, ps}; Point(22) = {0.03, -R-0.005, 0, ps}; Point(23) = {0.03, -R, 0, ps}; Point(24) = {-0.03, -R, 0, ps};
Line(21) = {21,22}; Line(22) = {22,23}; Line(23) = {23,24}; Line(24) = {24,21};
Curve Loop(3) = {21,22,23,24}; Plane Surface(3) = {3};
Physical Surface("rock") = {1};
Physical Surface("platen_top") = {2};
Physical Surface("platen_bottom") = {3};
Physical Curve("rim") = {1,2,3,4};
