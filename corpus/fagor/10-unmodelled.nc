; What the interpreter does not model is kept and named, never skipped: a canned cycle (NC416), the
; positioning while it is modal (NC416), a chamfer and an inclined plane (NC415).
%CYCLES
G00 X10 Y10 Z10
G81 Z2 I-10
X20
G80
G39 I2
#CS ON [1] [MODE 1, 0, 0, 0, 30, 0, 0]
#CS OFF
G00 X0 Y0
M30
