; Coordinate rotation G73 (incremental: Q adds up), scale G72, mirror G11/G12 (cumulative), G14 by
; axis sign and G10 cancel (spec §10.4-10.6; like the manual's profile x4 with $FOR and G73 Q).
%FRAMES
G00 X0 Y0 Z0
$FOR P1 = 1, 4, 1
  G73 Q90
  G01 X10 Y0 F500
  G00 X0 Y0
$ENDFOR
G73
G72 S2
G01 X5 Y5
G72
G11
G01 X5 Y5
G12
G01 X5 Y5
G14 X1
G01 X5 Y5
G10
G01 X5 Y5
M30
