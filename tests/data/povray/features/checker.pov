// checker.yaml's twin. POV-Ray's matrix is given by columns of rtcli's rows.
#include "_head.inc"
Camera(<0, 2.2, -6>, <0, 0.8, 0>, 60)
background { color rgb <0.4, 0.6, 0.9> }
light_source { <3, 8, -4> color rgb <1, 1, 1> }
union {
  plane { y, 0 pigment { checker color rgb <0.9, 0.9, 0.85> color rgb <0.2, 0.25, 0.5> } finish { ambient 0.2 diffuse 0.8 } }
  sphere { 0, 1
    pigment { checker color rgb <240, 192, 32> / 255 color rgb <32, 64, 160> / 255 scale 0.5 }
    finish { ambient 0.2 diffuse 0.8 phong 0.3 phong_size 30 }
    scale <1.3, 0.7, 0.7> rotate <0, 0, 30> translate <-1.2, 1.1, 0.5> }
  box { <-0.6, 0, -0.6>, <0.6, 1.2, 0.6>
    pigment { checker color rgb <0.9, 0.3, 0.3> color rgb <0.95, 0.95, 0.9> scale 0.3 }
    finish { ambient 0.2 diffuse 0.8 }
    matrix <1, 0, 0,  0.4, 1, 0.2,  0, 0, 1,  0, 0, 0> rotate <0, -30, 0> translate <1.3, 0, 0.3> }
  transform Mirror }
