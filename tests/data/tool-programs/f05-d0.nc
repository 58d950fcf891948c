; Fagor 8065 mill: D0 cancels length and radius, then D1 again
G90 G17 G71
T5 D1 M6
G0 X0 Y0 Z20
G1 Z-1 F100
D0
G0 Z20
D1
G41 G1 X10 Y10 F200
G1 X30
G40 G1 X40 Y0
M30
