"""The compiled functions' machine code made ready: loaded from numba's on-disk cache, or compiled.

numba compiles a function the first time it is called, then keeps the machine code on disk
(numba_cache.cache_location() says where): a later process loads it in a fraction of a second,
but the first one spends about half a minute compiling the integrator. That time is never
silent: `ready` says on stderr that it compiles, where the code will be cached and, after,
how long it took; and it returns the time apart (RenderStats.load_seconds, compile_seconds),
so that no render counts it as tracing.

Whether a call will compile is known before it is made, from numba's index file of the
function (the .nbi beside its cached code): numba loads the code when that index, for this
numba version and the function's source file as it is now (its content hash), has an entry for
this CPU and the function's bytecode; otherwise it compiles. drop_stale_cache has already
emptied the cache if any of rtcli's other sources changed. Reading the index is a look into
numba's internals, so the answer is only a forecast: what happened is read after the call from
numba's own count of cache misses (Dispatcher.stats), which decides what is reported.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from rtcli.kernels import numba_cache


@dataclass
class Load:
    """Start-up of a compiled engine: seconds to import numba, pack the scene and load or compile
    the machine code, and of those the seconds spent compiling (0 when it came from the cache)."""

    seconds: float = 0.0
    compile_seconds: float = 0.0

    def __add__(self, other: "Load") -> "Load":
        return Load(self.seconds + other.seconds, self.compile_seconds + other.compile_seconds)


def say(text: str) -> None:
    """The default for notes: a `note:` line on stderr."""
    print(f"note: {text}", file=sys.stderr, flush=True)


def cached(dispatcher) -> bool | None:
    """Whether numba's cache holds machine code of `dispatcher` that it would load here (for this
    CPU, numba version and source), from its index file; None when that cannot be told."""
    try:
        cache = dispatcher._cache
        index = cache._cache_file._load_index()          # {} when missing, stale or of another numba
        codegen = dispatcher.targetctx.codegen()
        return any(key == cache._index_key(key[0], codegen) for key in index)
    except Exception:                                      # another numba's internals: no forecast
        return None


def _misses(dispatchers) -> int:
    try:
        return sum(sum(d.stats.cache_misses.values()) for d in dispatchers)
    except Exception:
        return 0


def functions(entries: list) -> dict:
    """The numba functions `entries` are made of, by id: themselves and every compiled function they
    call, found through the names their code reads (a compiled variant's globals are its callees)."""
    found, todo = {}, list(entries)
    while todo:
        d = todo.pop()
        if id(d) in found or not hasattr(d, "py_func"):
            continue
        found[id(d)] = d
        scope = getattr(d.py_func, "__globals__", {})
        todo.extend(scope.get(name) for name in getattr(d.py_func, "__code__", None).co_names if name in scope)
    return found


class Progress:
    """While numba compiles `entries`, says every `period` seconds how many of the functions they are
    made of it has compiled (or loaded from the cache) and for how long it has been at it, from numba's
    compile events: a minute is never silent."""

    PERIOD = 5.0

    def __init__(self, entries: list, what: str, notes: Callable[[str], None], period: float | None = None):
        self.what, self.notes, self.period = what, notes, self.PERIOD if period is None else period
        self.todo = functions(entries)
        self.done = {i for i, d in self.todo.items() if getattr(d, "signatures", None)}   # in memory already
        self.stop, self.began = threading.Event(), time.perf_counter()

    def __enter__(self):
        from numba.core import event  # start-up: numba is loaded already when something compiles
        self.listener = _listener(self.todo, self.done)
        event.register("numba:compile", self.listener)
        self.thread = threading.Thread(target=self._tell, daemon=True, name="rtcli compile progress")
        self.thread.start()
        return self

    def __exit__(self, *exc):
        from numba.core import event  # start-up: as above
        self.stop.set()
        self.thread.join()
        event.unregister("numba:compile", self.listener)

    def line(self) -> str:
        return (f"compiling {self.what}: {len(self.done)} of {len(self.todo)} functions, "
                f"{time.perf_counter() - self.began:.0f} s")

    def _tell(self) -> None:
        while not self.stop.wait(self.period):
            self.notes(self.line())


def _listener(todo: set, done: set):
    """A numba event listener adding to `done` each function of `todo` whose compile (or load) ended."""
    from numba.core.event import Listener  # start-up: as above

    class Heard(Listener):
        def on_start(self, event):
            pass

        def on_end(self, event):
            d = (event.data or {}).get("dispatcher")
            if id(d) in todo:
                done.add(id(d))
    return Heard()


def ready(entries: list, call: Callable[[], object], what: str, about: str,
          notes: Callable[[str], None] | None = None, start: float | None = None,
          period: float | None = None) -> Load:
    """Run `call`, which calls the compiled functions `entries` a first time, so that their machine
    code is loaded from the cache or compiled. When that compiles, say so on `notes` (default:
    stderr) before, with `what` is compiled, `about` how long it takes and where it is cached, and
    every `period` seconds (Progress.PERIOD) how far it has got while it compiles, and how long it took
after. The Load's seconds count from `start` (default: now)."""
    notes = notes or say
    start = time.perf_counter() if start is None else start
    todo = [d for d in entries if not d.signatures]          # in memory already: nothing to load
    where = numba_cache.cache_location()
    cold = bool(todo) and (not where.enabled or any(cached(d) is False for d in todo))
    if cold:
        notes(f"compiling {what}, once ({about}); " + (f"cached in {where}" if where.enabled else
                                                         f"not cached: {where.why} (see RTCLI_CACHE_DIR)"))
    misses, began = _misses(todo), time.perf_counter()
    if cold:
        with Progress(todo, what, notes, period):
            call()
    else:
        call()
    spent = time.perf_counter() - began
    compiled = _misses(todo) > misses
    if compiled:
        notes(f"compiled in {spent:.1f} s" if cold else
              f"compiled {what} in {spent:.1f} s (not found in the cache); cached in {where}")
    elif cold:
        notes(f"loaded from the cache in {spent:.1f} s")
    return Load(time.perf_counter() - start, spent if compiled else 0.0)
