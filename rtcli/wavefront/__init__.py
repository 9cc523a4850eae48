"""The numpy wavefront engine: arrays of rays, traced tile by tile (notes 000 11.7)."""
