; Programmable software limits G198 (lower) / G199 (upper): data for the machine check (spec §11.2).
%LIMITS
G90 G198 X-100 Y-50 Z-200
G199 X100 Y50 Z0
G00 X0 Y0 Z0
G01 X90 F1000
M30
