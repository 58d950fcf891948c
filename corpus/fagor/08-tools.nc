; Tools and technology: T with M06 (offset D1 implied: tool length on), spindle, dwell forms,
; radius compensation with the D radius, D0 cancels the length (spec §8, §11, §12). The test runs it
; on a machine with tool 1 (length 50, radius 2).
%TOOLS
T1 M6
S1000 M3
G00 X0 Y-10 Z5
G04 K0.5
G4 2
#TIME 1.5
G01 Z-1 F200
G41 G01 X0 Y0
G01 X20
G40 G01 X20 Y-10
G00 Z5 D0
M5
M30
