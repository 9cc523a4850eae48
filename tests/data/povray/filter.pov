#version 3.7;
// filter.yaml's twin: a tinted glass ball; POV-Ray filters light through it by its color.
#include "_common.inc"
sphere { <-0.3, 1.1, 0>, 0.9
  pigment { rgbf <0.9, 0.6, 0.3, 1> } finish { ambient 0 diffuse 0 } interior { ior 1.3 } }
