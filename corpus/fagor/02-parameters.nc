; Parameters, user variables and Fagor's expression rules: precedence, SQR is the square, MOD, **,
; hex constants, degrees, P values in address words (spec §6).
%PARAMS
P100 = 2 + 3 * 4
P101 = [2 + 3] * 4
P102 = SQR[3] + SQRT[16]
P103 = 7 MOD 4 + 2 ** 3
P104 = $1A
P105 = SIN[30] * 10
P106 = ABS[-2.5] + INT[4.9] + FUP[3.1]
P1 = 3
P1 += 2
V.P.DEPTH = -2
G00 XP100 YP101 Z5
G01 Z[V.P.DEPTH] F[P101 * 10]
X[P102] Y[P103]
X[P104 - P105] Y[P106]
XP1 Y-P1
M30
