// The fixture square with a surface group and a curve group that overlap others, so
// that entities sit in two physical groups. MSH 2.2 repeats such elements once per
// group; MSH 4.1 lists both groups in $Entities. Generated forms:
//   gmsh -2 multi.geo -format msh22 -o multi22a.msh     gmsh -2 multi.geo -format msh41 -bin -o multi41b.msh
Include "sq.geo";
Physical Surface("all") = {1, 2};
Physical Curve("bottom_left") = {1};
