// torus.yaml's twin.
#include "_head.inc"
Camera(<0, 3, -6>, <0, 0.7, 0>, 60)
background { color rgb <0.12, 0.12, 0.16> }
light_source { <5, 8, -6> color rgb <0.9, 0.9, 0.9> }
light_source { <-5, 3, -6> color rgb <0.3, 0.3, 0.3> }
union {
  plane { y, 0 Plain(1, 0.15, 0.6, 0, 1) }
  torus { 0.8, 0.35 rotate <90, 0, 0>
    pigment { checker color rgb <240, 240, 240> / 255 color rgb <192, 48, 48> / 255 scale 0.25 }
    finish { ambient 0.15 diffuse 0.8 phong 0.3 phong_size 32 }
    scale <1.3, 0.8, 1> rotate <60, 0, 0> rotate <0, 25, 0> translate <1.1, 1.0, 0.3> }
  torus { 1, 0.25 rotate <90, 0, 0> Plain(<0.2, 0.45, 0.8>, 0.1, 1, 0.5, 40)
    scale <1, 1, 1.8> rotate <90, 0, 0> translate <-1.2, 0.45, 0.2> }
  transform Mirror }
