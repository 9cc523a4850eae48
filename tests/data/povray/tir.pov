#version 3.7;
// tir.yaml's twin: a glass block; POV-Ray reflects at total internal reflection.
#include "_common.inc"
box { <-1, 0.01, -1>, <1, 1.6, 1>
  pigment { rgbf <1, 1, 1, 1> } finish { ambient 0 diffuse 0 } interior { ior 1.5 }
  rotate -35*y }
