"""The shared core: vectors, transforms, camera, lights, textures, materials, the scene model and the BVH."""
