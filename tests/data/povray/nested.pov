#version 3.7;
// nested.yaml's twin: an air bubble in glass, a glass ball in water, with POV-Ray's interiors.
#include "_common.inc"
#declare Clear = texture { pigment { rgbf <1, 1, 1, 1> } finish { ambient 0 diffuse 0 } }
sphere { <1.2, 1, 0>, 0.9 texture { Clear } interior { ior 1.5 } }
sphere { <1.0, 1.2, -0.3>, 0.4 texture { Clear } interior { ior 1.0 } no_shadow }
box { <-2.4, 0.01, -0.9>, <-0.2, 1.5, 0.9> texture { Clear } interior { ior 1.33 } }
sphere { <-1.3, 0.7, 0>, 0.5 texture { Clear } interior { ior 1.5 } }
