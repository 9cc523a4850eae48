"""The kernel machinery: how a kernel written once becomes its variants (variants.py, which will
move here later) and how the compiled entry points run as machine code files (machinecode/)."""
