; Fagor 8065 mill: outside contour of a 60 x 40 plate with radius compensation
G90 G17 G71 G94
T1 D1 M6
S2500 M3
G0 X-20 Y-20 Z10
G0 Z-5
G41 G1 X0 Y-10 F600
G1 Y40
G1 X60
G1 Y0
G1 X-10
G40 G1 X-20 Y-20
G0 Z10
M5
M30
