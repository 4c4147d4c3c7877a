// Welded machine frame on four elastic mounts, with a motor on the middle cross beam.
// 2.0 m x 1.0 m x 1.2 m (x, y, z), metres. Mesh with: gmsh -1 -format msh41 machine_frame.geo
h = 0.1;  // element size, m
// feet, rail level z = 0.3, top z = 1.2
Point(1) = {0, 0, 0, h};   Point(2) = {2, 0, 0, h};   Point(3) = {2, 1, 0, h};   Point(4) = {0, 1, 0, h};
Point(5) = {0, 0, 0.3, h}; Point(6) = {2, 0, 0.3, h}; Point(7) = {2, 1, 0.3, h}; Point(8) = {0, 1, 0.3, h};
Point(9) = {0, 0, 1.2, h}; Point(10) = {2, 0, 1.2, h}; Point(11) = {2, 1, 1.2, h}; Point(12) = {0, 1, 1.2, h};
Point(13) = {1, 0, 1.2, h}; Point(14) = {1, 1, 1.2, h};
Point(15) = {1, 0.35, 1.2, h}; Point(16) = {1, 0.65, 1.2, h};  // motor feet
Point(17) = {1, 0.5, 1.45, h};                                  // motor centre of mass
// columns (two pieces each: foot to rail, rail to top)
Line(1) = {1, 5}; Line(2) = {5, 9}; Line(3) = {2, 6}; Line(4) = {6, 10};
Line(5) = {3, 7}; Line(6) = {7, 11}; Line(7) = {4, 8}; Line(8) = {8, 12};
// top longitudinals (along x), split at the middle cross beam
Line(9) = {9, 13}; Line(10) = {13, 10}; Line(11) = {12, 14}; Line(12) = {14, 11};
// top cross beams (along y)
Line(13) = {9, 12}; Line(14) = {10, 11};
Line(15) = {13, 15}; Line(16) = {15, 16}; Line(17) = {16, 14};
// side rails at z = 0.3 (along x) and end rails (along y)
Line(18) = {5, 6}; Line(19) = {8, 7}; Line(20) = {5, 8}; Line(21) = {6, 7};
// diagonal brace in the back wall (y = 1)
Line(22) = {8, 14};
Physical Curve("columns") = {1, 2, 3, 4, 5, 6, 7, 8};
Physical Curve("longitudinals") = {9, 10, 11, 12};
Physical Curve("cross_beams") = {13, 14, 15, 16, 17};
Physical Curve("rails") = {18, 19, 20, 21};
Physical Curve("brace") = {22};
Physical Point("feet") = {1, 2, 3, 4};
Physical Point("foot_1") = {1};
Physical Point("foot_2") = {2};
Physical Point("foot_3") = {3};
Physical Point("foot_4") = {4};
Physical Point("motor_feet") = {15, 16};
Physical Point("motor") = {17};
