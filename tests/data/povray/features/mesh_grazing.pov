// mesh_grazing.yaml's twin: Mesh1 is the low-poly sphere with rtcli's corner normals.
#include "_head.inc"
#include "meshes.inc"
Camera(<0, 0.3, -3.1>, <0, 0.05, 0>, 60)
background { color rgb <0.12, 0.13, 0.16> }
light_source { <-30, 12, 4> color rgb <1, 1, 1> }
light_source { <20, -6, 9> color rgb <0.4, 0.5, 0.6> }
union {
  object { Mesh1 pigment { rgb <0.85, 0.55, 0.3> } finish { ambient rgb <0.06/0.85, 0.04/0.55, 0.02/0.3> diffuse 1 phong 0.3 phong_size 30 }
           scale <1.2, 1, 1> rotate <0, 10, 0> }
  transform Mirror }
