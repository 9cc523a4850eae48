// attenuated.yaml's twin: fade_distance 5 (c2 0.02), 2 (c1 0.25) and 2 (c2 0.125).
#include "_head.inc"
Camera(<0, 2.6, -6>, <0, 0.6, 0>, 60)
background { color rgb <0.02, 0.02, 0.03> }
light_source { <2, 1.5, -1> color rgb <1.6, 0.5, 0.3> fade_distance 5 fade_power 2 }
light_source { <-2, 1.2, 0.5> color rgb <0.3, 0.7, 1.8> fade_distance 2 fade_power 1 }
light_source { <0, 4, 2> color rgb <0.4, 0.9, 0.4> fade_distance 2 fade_power 2 }
union {
  plane { y, 0 Plain(1, 0.02, 0.8, 0, 1) }
  sphere { <-0.9, 0.5, 0.4>, 0.5 Plain(1, 0.02, 0.8, 0.4, 40) }
  sphere { <0.9, 0.5, 0.9>, 0.5 Plain(1, 0.02, 0.8, 0.4, 40) }
  sphere { 0, 1 Plain(1, 0.02, 0.8, 0, 1) scale <0.3, 0.6, 0.3> translate <0.1, 0.6, -0.6> }
  transform Mirror }
