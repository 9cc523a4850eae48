// quadrics.yaml's twin: rtcli's generic cylinder is |z| <= 1, its generic cone has its base at
// z = 0 (radius 1) and its tip at z = 1.
#include "_head.inc"
Camera(<0, 2.6, -6>, <0, 0.8, 0>, 60)
background { color rgb <0.3, 0.35, 0.45> }
light_source { <3, 7, -5> color rgb <0.9, 0.9, 0.9> }
light_source { <-4, 2, -4> color rgb <0.25, 0.25, 0.25> }
union {
  plane { y, 0 Plain(1, 0.15, 0.6, 0, 1) }
  cylinder { <0, 0, -1>, <0, 0, 1>, 1 Plain(<0.2, 0.4, 0.8>, 0.1, 1, 0.4, 40)
    scale <0.5, 0.3, 0.6> rotate <-60, 0, 0> rotate <0, 30, 0> translate <-2, 0.6, 0.6> }
  cylinder { <-0.5, 0, 1.2>, <-0.9, 1.5, 1.0>, 0.4 Plain(<0.8, 0.6, 0.2>, 0.1, 1, 0.4, 40) scale <1, 1, 0.6> }
  cone { <0, 0, 0>, 1, <0, 0, 1>, 0 Plain(<0.8, 0.2, 0.2>, 0.1, 1, 0.4, 40)
    scale <0.5, 0.8, -1.4> rotate <90, 0, 0> translate <0.6, 1.4, 0> }
  cone { <2.0, 0, 0.4>, 0.7, <1.8, 1.1, 0.4>, 0.3 Plain(<0.3, 0.7, 0.5>, 0.1, 1, 0.4, 40) scale <1.2, 1, 0.7> }
  transform Mirror }
