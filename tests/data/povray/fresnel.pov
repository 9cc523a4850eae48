#version 3.7;
// fresnel.yaml's twin: glass with Fresnel reflection and energy conservation.
#include "_common.inc"
sphere { <0, 1.1, 0>, 1
  pigment { rgbf <1, 1, 1, 1> } finish { ambient 0 diffuse 0 reflection { 0, 1 fresnel on } conserve_energy }
  interior { ior 1.5 } }
