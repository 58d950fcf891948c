; Fagor 8065 mill: a local subroutine cuts a slot with compensation, called twice
%L SLOT
G41 G1 X10 Y0 F300
G1 X40
G40 G1 X50 Y-10
#RET
%SLOTS
G90 G17 G71
T4 D1 M6
S2000 M3
G0 X0 Y-10 Z5
G1 Z-3 F150
#CALL SLOT
G0 Z5
G0 X0 Y-10
G1 Z-6 F150
#CALL SLOT
G0 Z50
M30
