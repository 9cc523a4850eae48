"""The kernel machinery: how a kernel written once becomes its variants (variants.py, in the ops
of vocabulary.py), where numba caches what it compiles (numba_cache.py), and how the compiled entry
points run as machine code files (machinecode/)."""
