; Zero offsets G54-G59 and G159=n, G53 cancel, G92 preset, G70 inch (spec §7). The test runs it on a
; machine with G55 X100 and G159=7 (= G54.1 P1 in the machine model) Y50.
%OFFSETS
G54 G00 X0 Y0 Z0
G55 X10
G159=7 X0 Y0
G53 X5 Y5
G92 X0 Y0
G00 X10
G70 G00 X1
G71
M30
