// mesh_textured.yaml's twin; Mesh1 is Spot, with its corner (u, v). rtcli's vertical fov of 40
// degrees is POV-Ray's horizontal angle 2 atan(tan(20 degrees) 4 / 3) at 4:3.
#include "_head.inc"
#include "meshes.inc"
Camera(<2.2, 1.2, 2.6>, <0, 0.05, 0.1>, 51.774008759)
background { color rgb <0.55, 0.7, 0.85> }
light_source { <-4, 6, 5> color rgb <0.85, 0.85, 0.85> }
light_source { <4, 2, 3> color rgb <0.25, 0.25, 0.25> }
union {
  plane { y, -0.737 Plain(1, 0.2, 0.6, 0, 1) }
  object { Mesh1
    texture { pigment { uv_mapping image_map { png "spot_texture.png" gamma 1.0 interpolate 2 } }
              finish { ambient 0.25 diffuse 0.8 phong 0.15 phong_size 20 } }
    scale <1, 1.15, 1> rotate <0, 215, 0> }
  transform Mirror }
