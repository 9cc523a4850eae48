"""The limits of a scene, in one place (docs/scene-format.md, "Limits").

They keep loading and rendering within bounded time and memory, and keep the
arithmetic of intersection and shading finite.
"""

MB = 1024 * 1024

# files (checked with os.stat before they are opened)
MAX_SCENE_BYTES = 64 * MB          # a scene file or an included file
MAX_MESH_BYTES = 256 * MB          # an OBJ file
MAX_IMAGE_BYTES = 256 * MB         # a texture image file
MAX_TEXTURE_PIXELS = 1 << 27       # texels of a texture: 134,217,728 (16384 x 8192), 3 bytes each

# YAML
MAX_DEPTH = 200                    # mappings and lists inside one another
ALIAS_BUDGET = 1_000_000           # values that aliases and merge keys may repeat in one file
MAX_INCLUDE_DEPTH = 32             # files including one another

# numbers: every number of a scene, and every entry of an object's composed transform
# and of its inverse, lies within +-MAX_MAGNITUDE. The intersection formulas raise
# lengths to powers up to the 12th (the torus's resolvent cubic): 1e20 ** 12 stays
# far below the largest double, 1.8e308.
MAX_MAGNITUDE = 1e20
RANGE = "between -1e20 and 1e20"   # how messages name it

# scene and image
MAX_OBJECTS = 1_000_000            # objects of a scene (csg children and mesh triangles not counted)
MAX_SIDE = 32768                   # image width or height
MAX_PIXELS = 1 << 28               # width x height: 268,435,456 (16384 x 16384)
