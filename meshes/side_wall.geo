// Side wall of a machine with two bearing bores, a steel plate in the plane y = 0,
// 1.6 m long (x) and 1.0 m high (z), metres. The strips round the bores are meshed with
// triangles, the plain strips in between with quads (recombined).
// Physical surfaces "wall" (all of it), "wall_quads", "wall_triangles"; curves "bore_1",
// "bore_2" (bore edges: line cells, use their nodes for interpolating links) and "base"
// (bottom edge, z = 0); points "bearing_1", "bearing_2" (bore centres, not meshed with
// the plate).
// Mesh with the gmsh Python module (see meshes/README.md).
SetFactory("OpenCASCADE");
Lw = 1.6; Hw = 1.0;                          // wall, m
x1 = 0.45; z1 = 0.60; r1 = 0.080;            // bore 1: centre (x, z) and radius, m
x2 = 1.15; z2 = 0.55; r2 = 0.065;            // bore 2
cuts[] = {0.25, 0.65, 0.95, 1.35};           // strip boundaries (x), m
h = 0.04;                                    // element size, m
e = 1e-6;

Rectangle(1) = {0, 0, 0, cuts[0], Hw};
Rectangle(2) = {cuts[0], 0, 0, cuts[1] - cuts[0], Hw};
Rectangle(3) = {cuts[1], 0, 0, cuts[2] - cuts[1], Hw};
Rectangle(4) = {cuts[2], 0, 0, cuts[3] - cuts[2], Hw};
Rectangle(5) = {cuts[3], 0, 0, Lw - cuts[3], Hw};
Disk(6) = {x1, z1, 0, r1};
Disk(7) = {x2, z2, 0, r2};
BooleanDifference{ Surface{2}; Delete; }{ Surface{6}; Delete; }
BooleanDifference{ Surface{4}; Delete; }{ Surface{7}; Delete; }
BooleanFragments{ Surface{:}; Delete; }{}
Rotate {{1, 0, 0}, {0, 0, 0}, Pi/2} { Surface{:}; }
Point(1000) = {x1, 0, z1};
Point(1001) = {x2, 0, z2};

quads() = Surface In BoundingBox{-e, -e, -e, cuts[0] + e, e, Hw + e};
quads() += Surface In BoundingBox{cuts[1] - e, -e, -e, cuts[2] + e, e, Hw + e};
quads() += Surface In BoundingBox{cuts[3] - e, -e, -e, Lw + e, e, Hw + e};
tris() = Surface In BoundingBox{cuts[0] - e, -e, -e, cuts[1] + e, e, Hw + e};
tris() += Surface In BoundingBox{cuts[2] - e, -e, -e, cuts[3] + e, e, Hw + e};
Recombine Surface{quads()};
Physical Surface("wall") = {quads(), tris()};
Physical Surface("wall_quads") = {quads()};
Physical Surface("wall_triangles") = {tris()};
Physical Curve("bore_1") = Curve In BoundingBox{x1 - r1 - e, -e, z1 - r1 - e, x1 + r1 + e, e, z1 + r1 + e};
Physical Curve("bore_2") = Curve In BoundingBox{x2 - r2 - e, -e, z2 - r2 - e, x2 + r2 + e, e, z2 + r2 + e};
Physical Curve("base") = Curve In BoundingBox{-e, -e, -e, Lw + e, e, e};
Physical Point("bearing_1") = {1000};
Physical Point("bearing_2") = {1001};

Mesh.MeshSizeMax = h;
Mesh.MeshSizeMin = 0.5 * h;
Mesh.Algorithm = 6;           // frontal-Delaunay triangles; the quad strips are recombined
Mesh.RecombinationAlgorithm = 1;
Mesh.MshFileVersion = 4.1;
