"""Where the cluster is (README.md, Clusters): a scheduler's address, a scheduler file, or a
LocalCluster started for the command; and Dask's connect timeout, which bounds the waits."""

from __future__ import annotations

import re
from dataclasses import dataclass

from rtcli.cluster.schedulerfile import scheduler_address
from rtcli.errors import RtcliError, plural, shown

INSTALL = "pip install -e '.[cluster]' in the rtcli folder (rtcli is not on the package index)"


# --- where the cluster is ---
@dataclass(frozen=True)
class Target:
    """The cluster: a scheduler's address, a scheduler file, or a LocalCluster of `local` workers."""

    address: str | None = None
    file: str | None = None
    local: int = 0

    def __str__(self) -> str:
        if self.local:
            return f"a local cluster of {plural(self.local, 'worker')}"
        return f"the Dask scheduler at {shown(self.address)}"


def target(address: str | None, file: str | None, local: int | None) -> Target | None:
    """The Target the options name (at most one of them), or None."""
    given = [name for name, value in (("--cluster", address), ("--cluster-file", file),
                                      ("--local-cluster", local)) if value]
    if len(given) > 1:
        raise RtcliError(f"{' and '.join(given)}: give one way to reach a cluster")
    if not given:
        return None
    if file:
        address = scheduler_address(file)
    if address:
        address = _checked_address(address, f"--cluster-file {shown(file)}: its address" if file else "--cluster")
    return Target(address, file, local or 0)


def _checked_address(address: str, what: str) -> str:
    """A scheduler's address as Dask takes it, tcp:// added when no scheme is given."""
    full = address if "://" in address else f"tcp://{address}"
    if not re.fullmatch(r"(tcp|tls|ws|wss)://(\[[0-9a-fA-F:.]+\]|[^\s/:\[\]]+):\d{1,5}", full):
        raise RtcliError(f"{what} {shown(address)}: give the scheduler's address as tcp://HOST:PORT")
    return full


def load_distributed():
    try:
        import distributed  # the cluster extra, optional: loaded when a command asks for a cluster
    except ImportError:
        raise RtcliError(f"a cluster needs Dask's distributed scheduler, which is not installed: {INSTALL}") \
            from None
    return distributed


def connect_timeout() -> float:
    """Dask's connect timeout (distributed.comm.timeouts.connect), in seconds."""
    import dask  # the cluster extra, optional: loaded when a command asks for a cluster
    from dask.utils import parse_timedelta
    return parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), "s")
