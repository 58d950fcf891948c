; Fagor 8065 mill: finishing pass written for whatever tool is in the spindle
G90 G17 G71
S1500 M3
G0 X-10 Y-10 Z2
G1 Z-1 F100
G42 D1 G1 X0 Y0 F300
G1 X40
G1 Y30
G40 G1 X50 Y40
G0 Z20
M30
