"""Machine code files: the compiled entry points run without loading numba.

numba's on-disk cache saves the minute of compiling, but a process that loads it still
imports numba and sets up its typing and lowering tables, about 0.4 s of every render:
more than the whole trace of a 640x480 image, and up to a second more when the 180 MB
LLVM library has to come back from disk. So when numba has compiled an entry point (the
integrator's entry, compiled/tracing.py's trace_camera; the BVH build, core/bvh_build.py's
levels), `make` also writes its machine code as a small shared library beside numba's
cache (position-independent object code from numba's optimised module, linked by the C
compiler, `cc`), and `load` opens it with ctypes: no numba, no LLVM, about a millisecond.
It is the same code numba runs: the entry is wrapped in a C function (numba's cfunc) that
rebuilds the arguments from a flat list of words, so the pixels are the same bit for bit
(tests/kernels/test_machinecode.py).

The arguments of an entry are arrays, numbers, bools and namedtuples of those (the
compiled engine's Geometry and Looks). Their `layout` (each leaf's kind, an array's dtype
and number of dimensions, a namedtuple's fields) is fixed when the file is made; a call
passes each array as its address and shape (C-contiguous, aligned arrays only), each int
and bool as a word and each float as a float. A file is used only when its key matches
this process: rtcli's sources (the fingerprint compiled.drop_stale_cache keeps) and this
package's, the CPU (its model and feature flags), numba, llvmlite and Python; and a call
only when its arguments have the file's layout. Otherwise the caller takes numba's path,
which is slower to start and gives the same numbers. Without a C compiler no file is
made, and renders load numba as before.

Trust (docs/architecture.md, Trust in the machine code files). Opening a shared library
runs its code, so a file is opened only when its folder, its description and its library
belong to this user and are writable by no one else, the two files are regular files
(looked at without following a link or opening a FIFO or a device), and the library's
bytes have the SHA-256 the description recorded when it was written. The library is read
once, checked, and opened from a sealed copy in memory (an anonymous memfd on Linux, else a
copy in a private folder): the bytes opened are the bytes checked. Anything that does not
pass means numba's path, said in one line to whoever listens (`report_to`: `--stats`).

Entries allocate nothing (the caller passes the output and scratch arrays), so the code
needs neither numba's runtime nor its helpers: `helper_calls` reads the module and finds
the calls of numba's helpers (NRT_*, numba_*) and of Python's C API that a call can make
without raising an exception; a module with one is refused when it is written. The
others lie on the paths that raise an exception, which rtcli's kernels never take; they
are linked to stubs that leave the machine code at once (a longjmp to the C function
rtcli calls), so the call returns to Python, which raises Stopped: never abort().

Writing is atomic: the library's name holds a hash of its bytes, and the description
(.json), replaced last, names it and records its SHA-256.

The modules, by what they do:
  arguments.py  an entry's arguments: their layout, passed as words and floats, and the
                cfunc that rebuilds them
  places.py     the switch (RTCLI_MACHINE_CODE), the key, the folder, the description's name
  writing.py    `make`: numba's module emitted, linked by `cc`, committed (needs numba)
  llvmir.py     numba's optimised module read as text
  flow.py       `helper_calls`: which of numba's helpers a call can reach
  trust.py      which files may be opened, and opening exactly the bytes checked
  entries.py    `load`, `entry`, Entry, Stopped and `report_to` (ctypes only)
"""

from rtcli.kernels.machinecode.entries import Entry, Stopped, entry, load, report_to
from rtcli.kernels.machinecode.places import description_file, folder, sources_digest
from rtcli.kernels.machinecode.writing import make

__all__ = ["Entry", "Stopped", "description_file", "entry", "folder", "load", "make", "report_to", "sources_digest"]
