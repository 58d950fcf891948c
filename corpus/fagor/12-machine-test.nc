; A program in the manner of a machine builder's test program: V. variables, messages, a local
; subroutine with a loop, $IF on a system value, #PATH and synchronisation that do not move.
%L WARMUP
$FOR P20 = 1, 2, 1
  G01 X[50 * P20] Y0 F2000
  G01 X0
$ENDFOR
M29
%MTBTEST
#PATH ["C:\CNC8070\USERS\SUB"]
#MSG ["Axis test"]
G17 G71 G90 G94
T2 M6
G00 X0 Y0 Z50
P100 = V.A.PPOS.Z
$IF P100 > 10
  G00 Z[P100 - 40]
$ELSE
  #WARNING ["Z below the safety plane"]
$ENDIF
P101 = V.G.TOOL
LL WARMUP
#FLUSH
G00 Z[P101 * 25]
#MSG [""]
M30
