;FLAVOR:Marlin
;cnccomp sample: 3D-printer style program (Marlin) for samples/machines/tilting-head-b.xml
M140 S60
M104 S210
M190 S60
M109 S210
G28 ;Home
G21
G90
M82 ;absolute extrusion
G92 E0
M117 Printing sample...
G1 Z15.0 F6000 ;Move the platform down 15mm
G0 F6000 X50.0 Y50.0 Z0.3
;LAYER:0
;TYPE:SKIRT
G1 F1500 X60.0 Y50.0 E0.5
G1 X60.0 Y60.0 E1.0
G1 X50.0 Y60.0 E1.5
G1 X50.0 Y50.0 E2.0
G2 X70.0 Y50.0 I10.0 J0.0 E3.2
G3 X50.0 Y50.0 R10.0 E4.4
;LAYER:1
G0 X55.0 Y55.0 Z0.5
G1 X65.5 Y55.25 E5.0
G10 ;retract
G11 ;unretract
M107
M104 S0
M140 S0
G28 X0 Y0
M84
