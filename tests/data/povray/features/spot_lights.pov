// spot_lights.yaml's twin.
#include "_head.inc"
Camera(<0, 3.2, -6>, <0, 0.4, 0>, 60)
background { color rgb <0.05, 0.05, 0.08> }
light_source { <2, 5, -1> color rgb <1, 0.85, 0.6> spotlight point_at <2, 5, -1> + <-0.3, -1, 0.2>
               radius 22 falloff 22 tightness 0 }
light_source { <-3, 4, -3> color rgb <0.5, 0.7, 1> spotlight point_at <-3, 4, -3> + <0.5, -0.8, 0.6>
               radius 30 falloff 30 tightness 6 }
union {
  plane { y, 0 Plain(1, 0.05, 0.8, 0, 1) }
  sphere { <-0.9, 0.6, 0.3>, 0.6 Plain(1, 0.05, 0.8, 0.5, 50) }
  sphere { 0, 1 Plain(1, 0.05, 0.8, 0, 1) scale <0.4, 0.7, 0.4> rotate <0, 0, 20> translate <1.1, 0.7, 0.5> }
  transform Mirror }
