; $ flow control: WHILE with CONTINUE, FOR with BREAK, DO .. ENDDO, SWITCH, IF/ELSEIF/ELSE with
; logical * of bracketed conditions, $IF .. $GOTO, $GOTO to a N<n>: target (spec §17).
%FLOW
G00 X0 Y0 Z0
P1 = 0
$WHILE P1 < 3
  P1 = P1 + 1
  $IF P1 == 2
    $CONTINUE
  $ENDIF
  G01 X[P1 * 10] F100
$ENDWHILE
$FOR P2 = 1, 5, 1
  $IF P2 == 4
    $BREAK
  $ENDIF
  G01 YP2
$ENDFOR
P3 = 0
$DO
  P3 = P3 + 2
$ENDDO P3 < 5
G01 Z-P3
$SWITCH P3
  $CASE 4
    G01 X100
    $BREAK
  $CASE 6
    G01 X60
    $BREAK
  $DEFAULT
    G01 X200
    $BREAK
$ENDSWITCH
$IF [P1 == 3] * [P2 == 4]
  G01 Y40
$ELSEIF P1 == 3
  G01 Y50
$ELSE
  G01 Y60
$ENDIF
$IF 1 + 2 == 3 $GOTO [SKIP]
G01 X999
[SKIP] G01 X70
$GOTO N20
G01 Y999
N20: G01 Y80
M30
