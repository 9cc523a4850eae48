// mesh_smooth.yaml's twin; Mesh1, Mesh2 are its meshes in file order (written by the test).
#include "_head.inc"
#include "meshes.inc"
Camera(<0, 2.2, -6>, <0, 0.8, 0>, 60)
background { color rgb <0.3, 0.35, 0.45> }
light_source { <4, 7, -5> color rgb <0.9, 0.9, 0.9> }
union {
  plane { y, 0 Plain(<0.5, 0.5, 0.45>, 0.3, 1, 0, 1) }
  object { Mesh1 Plain(<0.72, 0.36, 0.18>, 1/9, 1, 0.4, 40)
           scale 0.45 rotate <0, 30, 0> translate <-0.9, 0, 0.6> }
  object { Mesh2 Plain(<0.2, 0.6, 0.8>, 0.1, 1, 0.3, 30)
           translate <2.494, -1.251, -4.103> scale <0.75, 0.65, 0.75> rotate <0, 155, 0>
           translate <1.0, 0.75, 0.2> }
  transform Mirror }
