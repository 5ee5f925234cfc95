; WARNING: Cut is not within machine bounds of X[0,300], Y[0,400]

;    svg2gcode 3.3.7 (2026-12-02 02:42:29)
;    arguments: 
;      laser_power: 850,
;      movement_speed: 1000,
;      pixel_size: 0.1,
;      maximum_image_laser_power: 300,
;      image_movement_speed: 1200,
;      fan: False,
;      rapid_move: 10,
;      showimage: False,
;      x_axis_maximum_travel: 300,
;      y_axis_maximum_travel: 400,
;      image_noise: 0,
;      pass_depth: 0.0,
;      laser_mode: dynamic,
;      splitfile: False,
;      pathcut: False,
;      nofill: True,
;      image_poweroffset: 0,
;      image_overscan: 0,
;      image_showoverscan: False,
;      color_coded: 
;    Boundingbox: (X-25.0,Y-17.5:X25.0,Y17.5)
;    boundingbox center: (X0,Y0)
;    GRBL 1.1, unit=mm, absolute coordinates

; Machine settings:
;    rapid movement,
;    XY plane,
;    cutter compensation off,
;    coordinate system 1,
;    move 'unit'/min
G0 G17 G40 G54 G94

G21
G90
; pass #1

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X-25 Y17.500000
; F1200 mm/min, power S300
M4
G1 X25 S300 F1200
G1 Y-17.500000
G1 X-25
G1 Y17.500000

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X-8.750000 Y8.750000
; F1200 mm/min, power S300
M4
G1 X-8.788178 Y8.060245
G1 X-8.902244 Y7.378917
G1 X-9.090805 Y6.714339
G1 X-9.351558 Y6.074630
G1 X-9.681317 Y5.467606
G1 X-10.076053 Y4.900683
G1 X-10.530944 Y4.380785
G1 X-11.040433 Y3.914266
G1 X-11.598295 Y3.506823
G1 X-12.197715 Y3.163436
G1 X-12.831370 Y2.888299
G1 X-13.491518 Y2.684773
G1 X-14.170096 Y2.555344
G1 X-14.858812 Y2.501595
G1 X-15.549253 Y2.524181
G1 X-16.232984 Y2.622827
G1 X-16.901652 Y2.796327
G1 X-17.547088 Y3.042563
G1 X-18.161407 Y3.358525
G1 X-18.737103 Y3.740353
G1 X-19.267144 Y4.183384
G1 X-19.745053 Y4.682204
G1 X-20.164994 Y5.230719
G1 X-20.521835 Y5.822229
G1 X-20.811216 Y6.449507
G1 X-21.029603 Y7.104889
G1 X-21.174327 Y7.780370
G1 X-21.243621 Y8.467696
G1 X-21.250000 Y8.750000
G1 X-21.211822 Y9.439755
G1 X-21.097756 Y10.121083
G1 X-20.909195 Y10.785661
G1 X-20.648442 Y11.425370
G1 X-20.318683 Y12.032394
G1 X-19.923947 Y12.599317
G1 X-19.469056 Y13.119215
G1 X-18.959567 Y13.585734
G1 X-18.401705 Y13.993177
G1 X-17.802285 Y14.336564
G1 X-17.168630 Y14.611701
G1 X-16.508482 Y14.815227
G1 X-15.829904 Y14.944656
G1 X-15.141188 Y14.998405
G1 X-14.450747 Y14.975819
G1 X-13.767016 Y14.877173
G1 X-13.098348 Y14.703673
G1 X-12.452912 Y14.457437
G1 X-11.838593 Y14.141475
G1 X-11.262897 Y13.759647
G1 X-10.732856 Y13.316616
G1 X-10.254947 Y12.817796
G1 X-9.835006 Y12.269281
G1 X-9.478165 Y11.677771
G1 X-9.188784 Y11.050493
G1 X-8.970397 Y10.395111
G1 X-8.825673 Y9.719630
G1 X-8.756379 Y9.032304
G1 X-8.750000 Y8.750000

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X5
; F1200 mm/min, power S300
M4
G1 X4.963052 Y8.143276
G1 X4.852754 Y7.545518
G1 X4.670737 Y6.965562
G1 X4.419690 Y6.411979
G1 X4.103323 Y5.892949
G1 X3.726313 Y5.416145
G1 X3.294231 Y4.988611
G1 X2.813463 Y4.616669
G1 X2.291114 Y4.305813
G1 X1.734904 Y4.060639
G1 X1.153054 Y3.884770
G1 X0.554163 Y3.780805
G1 X-0.052918 Y3.750280
G1 X-0.659217 Y3.793647
G1 X-1.255774 Y3.910265
G1 X-1.833771 Y4.098411
G1 X-2.384667 Y4.355303
G1 X-2.900319 Y4.677145
G1 X-3.373107 Y5.059180
G1 X-3.796043 Y5.495763
G1 X-4.162876 Y5.980441
G1 X-4.468186 Y6.506050
G1 X-4.707460 Y7.064823
G1 X-4.877161 Y7.648502
G1 X-4.974782 Y8.248460
G1 X-5 Y8.750000
G1 X-4.963052 Y9.356724
G1 X-4.852754 Y9.954482
G1 X-4.670737 Y10.534438
G1 X-4.419690 Y11.088021
G1 X-4.103323 Y11.607051
G1 X-3.726313 Y12.083855
G1 X-3.294231 Y12.511389
G1 X-2.813463 Y12.883331
G1 X-2.291114 Y13.194187
G1 X-1.734904 Y13.439361
G1 X-1.153054 Y13.615230
G1 X-0.554163 Y13.719195
G1 X0.052918 Y13.749720
G1 X0.659217 Y13.706353
G1 X1.255774 Y13.589735
G1 X1.833771 Y13.401589
G1 X2.384667 Y13.144697
G1 X2.900319 Y12.822855
G1 X3.373107 Y12.440820
G1 X3.796043 Y12.004237
G1 X4.162876 Y11.519559
G1 X4.468186 Y10.993950
G1 X4.707460 Y10.435177
G1 X4.877161 Y9.851498
G1 X4.974782 Y9.251540
G1 X5 Y8.750000

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X18.750000
; F1200 mm/min, power S300
M4
G1 X18.716478 Y8.249712
G1 X18.616513 Y7.758368
G1 X18.451891 Y7.284753
G1 X18.225555 Y6.837334
G1 X17.941553 Y6.424109
G1 X17.604961 Y6.052468
G1 X17.221796 Y5.729053
G1 X16.798911 Y5.459647
G1 X16.343864 Y5.249067
G1 X15.864791 Y5.101077
G1 X15.370257 Y5.018323
G1 X14.869104 Y5.002285
G1 X14.370291 Y5.053249
G1 X13.882736 Y5.170304
G1 X13.415155 Y5.351358
G1 X12.975909 Y5.593173
G1 X12.572850 Y5.891427
G1 X12.213184 Y6.240786
G1 X11.903341 Y6.635006
G1 X11.648860 Y7.067038
G1 X11.454292 Y7.529158
G1 X11.323115 Y8.013104
G1 X11.257673 Y8.510225
G1 X11.250000 Y8.750000
G1 X11.283522 Y9.250288
G1 X11.383487 Y9.741632
G1 X11.548109 Y10.215247
G1 X11.774445 Y10.662666
G1 X12.058447 Y11.075891
G1 X12.395039 Y11.447532
G1 X12.778204 Y11.770947
G1 X13.201089 Y12.040353
G1 X13.656136 Y12.250933
G1 X14.135209 Y12.398923
G1 X14.629743 Y12.481677
G1 X15.130896 Y12.497715
G1 X15.629709 Y12.446751
G1 X16.117264 Y12.329696
G1 X16.584845 Y12.148642
G1 X17.024091 Y11.906827
G1 X17.427150 Y11.608573
G1 X17.786816 Y11.259214
G1 X18.096659 Y10.864994
G1 X18.351140 Y10.432962
G1 X18.545708 Y9.970842
G1 X18.676885 Y9.486896
G1 X18.742327 Y8.989775
G1 X18.750000 Y8.750000

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X-18.740790 Y-2.500000
; F1200 mm/min, power S300
M4
G1 X-16.162090
G1 Y-10.550904
G1 X-11.634293
G1 Y-12.500000
G1 X-18.740790
G1 Y-2.500000

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X-3.931681 Y-10.678165
; F1200 mm/min, power S300
M4
G1 X-7.963831
G1 X-8.600134 Y-12.500000
G1 X-11.192230
G1 X-7.488279 Y-2.500000
G1 X-4.413932
G1 X-0.709980 Y-12.500000
G1 X-3.302076
G1 X-3.931681 Y-10.678165

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X-7.320831 Y-8.822840
; F1200 mm/min, power S300
M4
G1 X-4.581380
G1 X-5.947756 Y-4.844273
G1 X-7.320831 Y-8.822840

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X5 Y-14
; F1200 mm/min, power S300
M4
G1 X6.800000

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X8
; F1200 mm/min, power S300
M4
G1 X9.800000

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X11
; F1200 mm/min, power S300
M4
G1 X12.800000

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X14
; F1200 mm/min, power S300
M4
G1 X15.800000

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X17
; F1200 mm/min, power S300
M4
G1 X18.800000

; default action: engrave path '', color '#000000'

; delta: 0
M5
G0 X20
; F1200 mm/min, power S300
M4
G1 X21.800000

; default action: engrave path '', color '#303030'

; delta: 0
M5
G0 X5 Y-12
; F1200 mm/min, power S244
M4
G1 X6.800000 S244

; default action: engrave path '', color '#303030'

; delta: 0
M5
G0 X8
; F1200 mm/min, power S244
M4
G1 X9.800000

; default action: engrave path '', color '#303030'

; delta: 0
M5
G0 X11
; F1200 mm/min, power S244
M4
G1 X12.800000

; default action: engrave path '', color '#303030'

; delta: 0
M5
G0 X14
; F1200 mm/min, power S244
M4
G1 X15.800000

; default action: engrave path '', color '#303030'

; delta: 0
M5
G0 X17
; F1200 mm/min, power S244
M4
G1 X18.800000

; default action: engrave path '', color '#303030'

; delta: 0
M5
G0 X20
; F1200 mm/min, power S244
M4
G1 X21.800000

; default action: engrave path '', color '#606060'

; delta: 0
M5
G0 X5 Y-10
; F1200 mm/min, power S187
M4
G1 X6.800000 S187

; default action: engrave path '', color '#606060'

; delta: 0
M5
G0 X8
; F1200 mm/min, power S187
M4
G1 X9.800000

; default action: engrave path '', color '#606060'

; delta: 0
M5
G0 X11
; F1200 mm/min, power S187
M4
G1 X12.800000

; default action: engrave path '', color '#606060'

; delta: 0
M5
G0 X14
; F1200 mm/min, power S187
M4
G1 X15.800000

; default action: engrave path '', color '#606060'

; delta: 0
M5
G0 X17
; F1200 mm/min, power S187
M4
G1 X18.800000

; default action: engrave path '', color '#606060'

; delta: 0
M5
G0 X20
; F1200 mm/min, power S187
M4
G1 X21.800000

; default action: engrave path '', color '#909090'

; delta: 0
M5
G0 X5 Y-8
; F1200 mm/min, power S131
M4
G1 X6.800000 S131

; default action: engrave path '', color '#909090'

; delta: 0
M5
G0 X8
; F1200 mm/min, power S131
M4
G1 X9.800000

; default action: engrave path '', color '#909090'

; delta: 0
M5
G0 X11
; F1200 mm/min, power S131
M4
G1 X12.800000

; default action: engrave path '', color '#909090'

; delta: 0
M5
G0 X14
; F1200 mm/min, power S131
M4
G1 X15.800000

; default action: engrave path '', color '#909090'

; delta: 0
M5
G0 X17
; F1200 mm/min, power S131
M4
G1 X18.800000

; default action: engrave path '', color '#909090'

; delta: 0
M5
G0 X20
; F1200 mm/min, power S131
M4
G1 X21.800000

; default action: engrave path '', color '#b0b0b0'

; delta: 0
M5
G0 X5 Y-6
; F1200 mm/min, power S94
M4
G1 X6.800000 S94

; default action: engrave path '', color '#b0b0b0'

; delta: 0
M5
G0 X8
; F1200 mm/min, power S94
M4
G1 X9.800000

; default action: engrave path '', color '#b0b0b0'

; delta: 0
M5
G0 X11
; F1200 mm/min, power S94
M4
G1 X12.800000

; default action: engrave path '', color '#b0b0b0'

; delta: 0
M5
G0 X14
; F1200 mm/min, power S94
M4
G1 X15.800000

; default action: engrave path '', color '#b0b0b0'

; delta: 0
M5
G0 X17
; F1200 mm/min, power S94
M4
G1 X18.800000

; default action: engrave path '', color '#b0b0b0'

; delta: 0
M5
G0 X20
; F1200 mm/min, power S94
M4
G1 X21.800000
M5
M2
