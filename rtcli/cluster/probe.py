"""Whether a Dask scheduler listens at an address, found out within the connect deadline
(docs/cluster.md, "Connecting"): a port that refuses, a peer that accepts and says nothing (a
dashboard's port, an 8786/8787 typo), one that speaks HTTP or another protocol, or a Dask worker
given for the scheduler, each in one line, before Dask's client (which would wait forever on a
silent peer, or read an HTTP answer as the length of a 3 EiB message) is started.

A Dask scheduler speaks first: it sends its handshake as soon as it accepts a connection. So
for tcp:// the first bytes tell: a Dask frame's length, "HTTP/...", anything else, or nothing.
Silence is then asked in HTTP, which a dashboard answers at once. Then Dask's own handshake and an
`identity` call say whether the peer is the scheduler (not a worker or a nanny).
"""

from __future__ import annotations

import asyncio
import contextlib
import random
import socket
import ssl
import struct
import threading
import time

from rtcli.cluster.target import connect_timeout
from rtcli.errors import RtcliError

DEFAULT_DEADLINE = 20.0           # seconds to connect, unless --cluster-timeout or Dask's shorter timeout says
ASK_AFTER = 2.0                   # seconds of a peer's silence before it is asked in HTTP ...
ASK_SHARE = 0.25                  # ... or this share of the deadline, when that is shorter
DASK_FRAME_AT_MOST = 1 << 26      # a Dask handshake's length is far below this (HTTP/ reads as 3 EiB)


def deadline(given: float | None) -> float:
    """The seconds a connection may take: --cluster-timeout's, else 20 s (or Dask's connect
    timeout, distributed.comm.timeouts.connect, when that is set shorter)."""
    return given if given is not None else min(DEFAULT_DEADLINE, connect_timeout())


class Clock:
    """What is left of a deadline of `seconds`, from now."""

    def __init__(self, seconds: float):
        self.seconds, self.end = seconds, time.monotonic() + seconds

    def left(self) -> float:
        return max(0.0, self.end - time.monotonic())


def probe(address: str, seconds: float, distributed) -> None:
    """RtcliError, in one line, unless a Dask scheduler answers at `address` (scheme://host:port,
    target.py checked it) within `seconds`."""
    clock = Clock(seconds)
    scheme, rest = address.split("://", 1)
    if scheme not in ("tcp", "tls", "ws", "wss"):         # inproc://, a scheduler in this process
        return
    host, port = rest.rsplit(":", 1)
    sock = _connected(address, host.strip("[]"), int(port), clock)
    with sock:
        if scheme == "tcp":                # tls and ws peers wait for the client's first word
            _sniffed(address, sock, clock, (host.strip("[]"), int(port)))
    _identity(address, clock, distributed)


def _connected(address: str, host: str, port: int, clock: Clock) -> socket.socket:
    """A TCP connection to host:port, tried again (as Dask does) while the peer refuses, until the
    deadline."""
    attempt = 0
    while True:
        try:
            return socket.create_connection((host, port), timeout=max(clock.left(), 0.01))
        except socket.gaierror as e:
            raise RtcliError(f"cannot reach the Dask scheduler at {address}: {host}: {e.strerror}") from None
        except (OverflowError, ValueError) as e:           # a port no socket can have
            raise RtcliError(f"cannot reach the Dask scheduler at {address}: {e}") from None
        except OSError:
            if clock.left() <= 0:
                raise RtcliError(f"cannot reach the Dask scheduler at {address}: Timed out trying to connect "
                                 f"to {address} after {clock.seconds:g} s") from None
        attempt += 1
        time.sleep(min(clock.left(), random.uniform(0, 0.01 * 2 ** min(attempt, 8))))


def _sniffed(address: str, sock: socket.socket, clock: Clock, where: tuple) -> None:
    """Return if the peer's first bytes are a Dask frame's; else RtcliError saying what it is. A peer
    silent for ASK_AFTER seconds is asked in HTTP (a scheduler slower than that still speaks first:
    its handshake comes whatever it was sent); one that hangs up then is asked in TLS, at `where`."""
    first = _received(sock, min(ASK_AFTER, clock.seconds * ASK_SHARE))
    if first is None:
        with contextlib.suppress(OSError):
            sock.sendall(b"GET / HTTP/1.0\r\n\r\n")
        first = _received(sock, clock.left())
        if first is None:
            raise _not_dask(address, f"accepted the connection but said nothing within {clock.seconds:g} s")
        if first == b"" and _speaks_tls(where, clock.left()):
            raise RtcliError(f"{address} speaks TLS: give it as tls://{address.split('://', 1)[1]}, with Dask's TLS "
                             "settings (docs/cluster.md, TLS)")
    if first.startswith(b"HTTP/"):
        raise _not_dask(address, "speaks HTTP (a web server, or a Dask dashboard)")
    if not first:
        raise _not_dask(address, "closed the connection without a word")
    while len(first) < 8 and (more := _received(sock, clock.left())):     # a frame's length may come in parts
        first += more
    if len(first) < 8 or struct.unpack("<Q", first[:8])[0] > DASK_FRAME_AT_MOST:
        raise _not_dask(address, f"answered in another protocol than Dask's (its first bytes: {first[:16]!r})")


def _speaks_tls(where: tuple, seconds: float) -> bool:
    """Whether the peer at (host, port) completes a TLS handshake within `seconds` (its certificate
    unchecked: only the protocol is asked)."""
    if seconds <= 0:
        return False
    context = ssl.create_default_context()
    context.check_hostname, context.verify_mode = False, ssl.CERT_NONE
    try:
        with socket.create_connection(where, timeout=seconds) as raw, context.wrap_socket(raw):
            return True
    except (OSError, ValueError):
        return False


def _received(sock: socket.socket, seconds: float) -> bytes | None:
    """Up to 64 bytes the peer sends within `seconds` (b"" if it closed), or None if it sent none."""
    if seconds <= 0:
        return None
    sock.settimeout(seconds)
    try:
        return sock.recv(64)
    except TimeoutError:
        return None
    except OSError:
        return b""


def _not_dask(address: str, what: str) -> RtcliError:
    return RtcliError(f"{address} is not a Dask scheduler: it {what}; give the address `dask scheduler` "
                      "prints (tcp://HOST:8786 by default; 8787 is its dashboard)")


def _identity(address: str, clock: Clock, distributed) -> None:
    """Dask's handshake and an `identity` call, in a thread of their own (the caller may have an
    event loop running) within the deadline: the peer must say it is a Scheduler."""
    found: dict = {}

    def run():
        try:
            found["type"] = asyncio.run(asyncio.wait_for(_ask(address, clock, distributed), clock.left()))
        except BaseException as e:                  # told in this thread's caller, below
            found["error"] = e
    thread = threading.Thread(target=run, name="rtcli-probe", daemon=True)
    thread.start()
    thread.join(clock.left() + 1)
    error, kind = found.get("error"), found.get("type")
    if (error is None and kind is None) or isinstance(error, TimeoutError):
        raise _not_dask(address, f"accepted the connection but did not answer as Dask does within "
                                 f"{clock.seconds:g} s")
    if isinstance(error, (ValueError, TypeError)) and "TLS" in str(error):
        raise RtcliError(f"{address}: Dask's TLS settings are missing here (distributed.comm.tls.ca-file, "
                         ".client.cert and .client.key; docs/cluster.md, TLS)") from None
    if error is not None and address.startswith("tls://"):
        detail = " ".join(str(error).split()) or type(error).__name__
        raise RtcliError(f"cannot reach the Dask scheduler at {address} in TLS ({detail}): a scheduler without TLS? "
                         f"then give tcp://{address.split('://', 1)[1]}") from None
    if isinstance(error, OSError) and not isinstance(error, ConnectionResetError):
        detail = " ".join(str(error).split()) or type(error).__name__
        raise RtcliError(f"cannot reach the Dask scheduler at {address}: {detail}") from None
    if error is not None:
        raise _not_dask(address, f"did not answer as Dask does ({type(error).__name__})")
    if kind != "Scheduler":
        raise RtcliError(f"{address} is a Dask {str(kind).lower()}, not the scheduler: give the address "
                         "`dask scheduler` prints (tcp://HOST:8786 by default)")


async def _ask(address: str, clock: Clock, distributed):
    """The `type` the peer's identity names, after Dask's handshake (with the security of Dask's
    configuration, as the client will use)."""
    args = distributed.Security().get_connection_args("client")
    comm = await distributed.comm.connect(address, timeout=max(clock.left(), 0.01), **args)
    try:
        await comm.write({"op": "identity", "reply": True})
        reply = await comm.read()
    finally:
        comm.abort()
    return reply.get("type") if isinstance(reply, dict) else None
