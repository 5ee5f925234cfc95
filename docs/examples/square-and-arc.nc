(The README's G-code example: a 40 mm line and a half circle, lit at S500)
$X
G21 G90
G0 X-20 Y-20
M3 S500
G1 X20 F1200
G2 X20 Y20 I0 J20
M5
G0 X0 Y0
