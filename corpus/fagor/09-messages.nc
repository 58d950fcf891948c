; Messages and block repetition: #MSG with a value, #WARNING, #ERROR in a branch not taken, #RPT of
; a numbered range twice (spec §16.1, §16.13).
%MSGS
#MSG ["starting %D", 1]
G00 X0 Y0 Z0
N10: G91 G01 X1 F100
N20: Y1
#RPT [N10, N20, 2]
G90
$IF 0
  #ERROR ["never"]
$ENDIF
#WARNING ["done"]
M30
