// A 5 cm square block resting on a long fixed base (seed paper, Section 3.2, Fig. 12).
// The block and the base touch along y = 0 but are separate bodies.
Geometry.AutoCoherence = 0;   // keep the block's corners off the base's top edge
If(!Exists(size)) size = 0.01; EndIf          // block element size [m]
If(!Exists(base_size)) base_size = 0.02; EndIf
If(!Exists(length)) length = 4.0; EndIf       // base length [m]
Point(1) = {-0.1, -0.02, 0, base_size};
Point(2) = {length, -0.02, 0, base_size};
Point(3) = {length, 0, 0, base_size};
Point(4) = {-0.1, 0, 0, base_size};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Point(5) = {0, 0, 0, size};
Point(6) = {0.05, 0, 0, size};
Point(7) = {0.05, 0.05, 0, size};
Point(8) = {0, 0.05, 0, size};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(2) = {2};
Physical Surface("base") = {1};
Physical Surface("block") = {2};
