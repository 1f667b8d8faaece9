// Fixture: a .geo with a syntax error (missing closing brace), for mesh_geo error tests.
Point(1) = {0, 0, 0, 0.1};
Line(1) = {1, 2;
