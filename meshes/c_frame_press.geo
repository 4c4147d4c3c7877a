// C-frame of a press as welded steel plates (shells), metres. Two C-shaped side plates
// (planes y = 0 and y = B; profile in x-z: D deep, Hc high, with the throat gap open to
// the front, x > xg, between the table z = z1 and the crown z = z2), the back plate
// (x = 0), the throat plate (x = xg, between table and crown), the table plate (z = z1)
// and the crown plate (z = z2) between the side plates.
// Physical surfaces "side_plates", "back_plate", "throat", "table", "crown"; points
// "foot_1".."foot_4" (bottom corners of the side plates), "feet" (all four),
// "table_centre" and "ram" (centres of the table and the crown plates, mesh nodes).
// Mesh with the gmsh Python module (see meshes/README.md).
SetFactory("OpenCASCADE");
D = 1.0; Hc = 2.0; B = 0.6;     // depth (x), height (z), distance of the side plates (y), m
xg = 0.4;                       // throat depth: the gap is open for x > xg, m
z1 = 0.8; z2 = 1.4;             // table and crown heights, m
h = 0.05;                       // element size, m
e = 1e-6;

// side plate y = 0: rectangle minus the gap in the xy plane, turned up about the x axis
Rectangle(1) = {0, 0, 0, D, Hc};
Rectangle(2) = {xg, z1, 0, D - xg + 0.1, z2 - z1};
BooleanDifference{ Surface{1}; Delete; }{ Surface{2}; Delete; }
Rotate {{1, 0, 0}, {0, 0, 0}, Pi/2} { Surface{1}; }
Translate {0, B, 0} { Duplicata{ Surface{1}; } }
// back plate x = 0 and throat plate x = xg
Rectangle(10) = {0, 0, 0, B, Hc};
Rotate {{1, 0, 0}, {0, 0, 0}, Pi/2} { Surface{10}; }
Rotate {{0, 0, 1}, {0, 0, 0}, Pi/2} { Surface{10}; }
Rectangle(11) = {0, z1, 0, B, z2 - z1};
Rotate {{1, 0, 0}, {0, 0, 0}, Pi/2} { Surface{11}; }
Rotate {{0, 0, 1}, {0, 0, 0}, Pi/2} { Surface{11}; }
Translate {xg, 0, 0} { Surface{11}; }
// table and crown plates with a centre point each (embedded: a node at the centre)
Rectangle(20) = {xg, 0, z1, D - xg, B};
Rectangle(21) = {xg, 0, z2, D - xg, B};
Point(1000) = {0.5 * (xg + D), 0.5 * B, z1};
Point(1001) = {0.5 * (xg + D), 0.5 * B, z2};
BooleanFragments{ Surface{:}; Point{1000, 1001}; Delete; }{}

Physical Surface("side_plates") = Surface In BoundingBox{-e, -e, -e, D + e, e, Hc + e};
Physical Surface("side_plates") += Surface In BoundingBox{-e, B - e, -e, D + e, B + e, Hc + e};
Physical Surface("back_plate") = Surface In BoundingBox{-e, -e, -e, e, B + e, Hc + e};
Physical Surface("throat") = Surface In BoundingBox{xg - e, -e, z1 - e, xg + e, B + e, z2 + e};
Physical Surface("table") = Surface In BoundingBox{xg - e, -e, z1 - e, D + e, B + e, z1 + e};
Physical Surface("crown") = Surface In BoundingBox{xg - e, -e, z2 - e, D + e, B + e, z2 + e};
f1() = Point In BoundingBox{-e, -e, -e, e, e, e};
f2() = Point In BoundingBox{D - e, -e, -e, D + e, e, e};
f3() = Point In BoundingBox{D - e, B - e, -e, D + e, B + e, e};
f4() = Point In BoundingBox{-e, B - e, -e, e, B + e, e};
Physical Point("foot_1") = {f1()};
Physical Point("foot_2") = {f2()};
Physical Point("foot_3") = {f3()};
Physical Point("foot_4") = {f4()};
Physical Point("feet") = {f1(), f2(), f3(), f4()};
Physical Point("table_centre") = Point In BoundingBox{0.5 * (xg + D) - e, 0.5 * B - e, z1 - e,
                                                      0.5 * (xg + D) + e, 0.5 * B + e, z1 + e};
Physical Point("ram") = Point In BoundingBox{0.5 * (xg + D) - e, 0.5 * B - e, z2 - e,
                                             0.5 * (xg + D) + e, 0.5 * B + e, z2 + e};

Mesh.MeshSizeMax = h;
Mesh.MeshSizeMin = 0.5 * h;
Mesh.Algorithm = 8;
Mesh.RecombineAll = 1;
Mesh.RecombinationAlgorithm = 1;
Mesh.MshFileVersion = 4.1;
