"""The scene-file edge: YAML loading, typed parameters, presets, OBJ reading and building a Scene.

The only code that knows YAML keys or reads input files.
"""
