// area_light.yaml's twin.
#include "_head.inc"
Camera(<0, 3, -6>, <0, 0.5, 0>, 60)
background { color rgb <0.3, 0.35, 0.45> }
light_source { <1.5, 4, -1> color rgb <0.95, 0.9, 0.8>
               area_light <-1.5, 0, 0>, <0, 0, 1.5>, 21, 21 area_illumination on }
union {
  plane { y, 0 Plain(1, 0.15, 0.8, 0, 1) }
  sphere { <-0.4, 0.7, 0.5>, 0.7 Plain(<0.75, 0.4, 0.25>, 0.04, 1, 0, 1) }
  box { <0.8, 0, -0.9>, <1.6, 1.2, -0.2> Plain(<0.25, 0.5, 0.75>, 0.04, 1, 0, 1) rotate <0, 20, 0> }
  transform Mirror }
