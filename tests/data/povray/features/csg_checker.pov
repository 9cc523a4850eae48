// csg_checker.yaml's twin: each child's pigment comes before its transforms (object space).
#include "_head.inc"
Camera(<0, 2.6, -6>, <0, 0.7, 0>, 60)
background { color rgb <0.3, 0.35, 0.45> }
light_source { <3, 8, -4> color rgb <1, 1, 1> }
#declare Warm = texture { pigment { checker color rgb <0.95, 0.8, 0.3> color rgb <0.6, 0.15, 0.1> scale 0.3 }
                          finish { ambient 0.2 diffuse 0.8 } }
#declare Cool = texture { pigment { checker color rgb <0.85, 0.9, 0.95> color rgb <0.1, 0.3, 0.6> scale 0.25 }
                          finish { ambient 0.2 diffuse 0.8 } }
union {
  plane { y, 0 pigment { rgb 1 } finish { ambient 0.2 diffuse 0.6 } }
  difference {
    box { <-0.7, -0.7, -0.7>, <0.7, 0.7, 0.7> texture { Warm } }
    sphere { 0, 1 texture { Cool } scale <0.9, 0.55, 0.7> Axis_Rotate_Trans(<1, 0, 1>, 35) translate <-0.3, 0.45, -0.5> }
    rotate <0, 25, 0> translate <1.3, 0.7, 0.2> }
  intersection {
    sphere { <0, 0, -0.9>, 1.3 texture { Warm } scale <1, 1.2, 1> }
    sphere { <0, 0, 0.9>, 1.3 texture { Cool } }
    rotate <-20, 0, 0> translate <-1.4, 1.0, 0> }
  union {
    sphere { 0, 0.5 texture { Cool } scale <1.4, 0.8, 1> rotate <0, 0, 30> }
    box { <-0.2, -0.5, -0.2>, <0.2, 0.5, 0.2> texture { Warm } translate <0.6, 0, 0> }
    translate <0, 0.5, -1.6> }
  transform Mirror }
