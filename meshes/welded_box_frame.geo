// Welded box frame: an open-bottom steel box of plates (top plate with a bearing bore,
// four side walls, one transverse rib plate) with a ring of flat-bar stiffeners welded
// round the side walls at mid height. 1.2 m x 0.8 m x 0.6 m (x, y, z), metres.
// Shells: physical surfaces "top_plate", "walls", "rib"; beams: physical curves
// "stiffeners"; "bore": the edge of the bearing bore (line cells: drop or use them as a
// node group for an interpolating link); points: "bearing" (bore centre), "foot_1".."foot_4"
// (bottom corners) and "feet" (all four).
// Mesh with the gmsh Python module (see meshes/README.md):
//   gmsh.open("welded_box_frame.geo"); gmsh.model.mesh.generate(2); gmsh.write(".msh")
SetFactory("OpenCASCADE");
L = 1.2; W = 0.8; H = 0.6;      // box, m
zs = 0.3;                       // stiffener height, m
xr = 0.8;                       // rib position, m
xb = 0.35; yb = 0.4; rb = 0.09; // bearing bore centre and radius, m
h = 0.05;                       // element size, m
e = 1e-6;                       // tolerance of the bounding-box selections, m

Rectangle(1) = {0, 0, H, L, W};
Disk(2) = {xb, yb, H, rb};
BooleanDifference{ Surface{1}; Delete; }{ Surface{2}; Delete; }
// side wall y = 0 (rectangle in the xy plane turned up about the x axis), then y = W
Rectangle(10) = {0, 0, 0, L, H};
Rotate {{1, 0, 0}, {0, 0, 0}, Pi/2} { Surface{10}; }
Translate {0, W, 0} { Duplicata{ Surface{10}; } }
// end wall x = 0 (turned up, then about z), x = L, and the rib at x = xr
Rectangle(20) = {0, 0, 0, W, H};
Rotate {{1, 0, 0}, {0, 0, 0}, Pi/2} { Surface{20}; }
Rotate {{0, 0, 1}, {0, 0, 0}, Pi/2} { Surface{20}; }
Translate {L, 0, 0} { Duplicata{ Surface{20}; } }
Translate {xr, 0, 0} { Duplicata{ Surface{20}; } }
// stiffener ring at z = zs
Point(101) = {0, 0, zs}; Point(102) = {L, 0, zs}; Point(103) = {L, W, zs}; Point(104) = {0, W, zs};
Line(101) = {101, 102}; Line(102) = {102, 103}; Line(103) = {103, 104}; Line(104) = {104, 101};
// make everything conforming: walls split at the stiffeners and the rib, shared edges
BooleanFragments{ Surface{:}; Curve{101, 102, 103, 104}; Delete; }{}
Point(1000) = {xb, yb, H};  // bearing centre (not meshed with the plates)

Physical Surface("top_plate") = Surface In BoundingBox{-e, -e, H - e, L + e, W + e, H + e};
walls() = Surface In BoundingBox{-e, -e, -e, L + e, e, H + e};
walls() += Surface In BoundingBox{-e, W - e, -e, L + e, W + e, H + e};
walls() += Surface In BoundingBox{-e, -e, -e, e, W + e, H + e};
walls() += Surface In BoundingBox{L - e, -e, -e, L + e, W + e, H + e};
Physical Surface("walls") = {walls()};
Physical Surface("rib") = Surface In BoundingBox{xr - e, -e, -e, xr + e, W + e, H + e};
Physical Curve("stiffeners") = Curve In BoundingBox{-e, -e, zs - e, L + e, W + e, zs + e};
Physical Curve("bore") = Curve In BoundingBox{xb - rb - e, yb - rb - e, H - e,
                                              xb + rb + e, yb + rb + e, H + e};
Physical Point("bearing") = {1000};
f1() = Point In BoundingBox{-e, -e, -e, e, e, e};
f2() = Point In BoundingBox{L - e, -e, -e, L + e, e, e};
f3() = Point In BoundingBox{L - e, W - e, -e, L + e, W + e, e};
f4() = Point In BoundingBox{-e, W - e, -e, e, W + e, e};
Physical Point("foot_1") = {f1()};
Physical Point("foot_2") = {f2()};
Physical Point("foot_3") = {f3()};
Physical Point("foot_4") = {f4()};
Physical Point("feet") = {f1(), f2(), f3(), f4()};

Mesh.MeshSizeMax = h;
Mesh.MeshSizeMin = 0.5 * h;
Mesh.Algorithm = 8;           // frontal-Delaunay for quads
Mesh.RecombineAll = 1;        // quads where possible, triangles elsewhere
Mesh.RecombinationAlgorithm = 1;
Mesh.MshFileVersion = 4.1;
