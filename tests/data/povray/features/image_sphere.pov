// image_sphere.yaml's twin: the picture's bytes used as they are (gamma 1.0), bilinear.
#include "_head.inc"
Camera(<0, 1.6, -5>, <0, 0.9, 0>, 60)
background { color rgb <0.3, 0.35, 0.45> }
light_source { <3, 6, -8> color rgb <0.9, 0.9, 0.9> }
#declare Grid = texture {
  pigment { uv_mapping image_map { png "uv_grid.png" gamma 1.0 interpolate 2 } scale <-1, 1, 1> translate <0.75, 0, 0> }
  finish { ambient 0.25 diffuse 0.75 } }
union {
  plane { y, 0 Plain(1, 0.2, 0.6, 0, 1) }
  sphere { <1.1, 1, 0>, 1 texture { Grid } }
  sphere { 0, 1 texture { Grid } rotate <0, 150, 0> scale <0.8, 1.1, 0.8> Axis_Rotate_Trans(<1, 0, 1>, 25) translate <-1.2, 1.2, 0.3> }
  transform Mirror }
