; Arcs: centre I J relative to the start point (also under G91), radius R (negative: more than half
; a circle), polar R Q about the work zero, G06 absolute centre for one block, G261/G262 modal
; centre mode, helix (spec §9.3-9.6).
%ARCS
G00 X0 Y0 Z0
G01 X10 F500
G03 X0 Y10 I-10 J0
G02 X10 Y20 R10
G01 R20 Q90
G02 G06 X20 Y0 I0 J0
G03 X20 Y0 I-10 J0 Z-5
G261 G03 X0 Y20 I0 J0
G262
G91 G02 X-10 Y-10 I0 J-10
G90 G02 X0 Y0 R-10
M30
