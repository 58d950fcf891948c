; Program structure: local subroutines before the main body, LL calls, block numbers and labels,
; both comment forms, a #COMMENT region and a block-skip block (spec §1.2, §2).
%L SQUARE
; a 10 mm square from the current corner, in incremental coordinates
G91 G01 X10 F600
Y10
X-10
Y-10
G90
M17
%L TWICE
LL SQUARE
LL SQUARE
#RET
%STRUCTURE
#COMMENT BEGIN
G00 X999 Y999 (never read: inside the comment region)
#COMMENT END
N10: G00 X0 Y0 Z5 (start) ; both comment forms on one block
/ G00 X1 Y1
G01 Z-1 F300
LL TWICE
[TOP] G00 Z5
M30
