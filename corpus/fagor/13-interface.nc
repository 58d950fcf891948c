; In the manner of a process cell's program: interface (V.E.) variables written for the HMI, a
; global subroutine called by its path, a #DEF macro, and a loop that an HMI flag ends (a value only
; the control knows: the analysis reports it, it does not guess it).
L C:\CNC8070\USERS\SUB\CELLSTART.NC
V.E.LAYERS=3            ; process data for the HMI
#DEF "BEAD"="G01 G91 X10 F600"
G92 G90 X0 Y0 Z0
$WHILE V.E.DONE == 0
  "BEAD"
$ENDWHILE
G00 Z50
M84                     ; an OEM M function
M30
