"""The workers a session leaves out (docs/cluster.md, "Workers with other software"): a worker
that cannot run this rtcli, or runs other software (its pixels could differ), is named in a
note and sent no more of this command's tasks; the tasks it refused run on the others. Only
when no worker is left that runs this rtcli is it an error. The worker itself is left alone: on a
shared cluster it may serve another client whose software it has.

A task that reaches such a worker fails at once (tasks.py checks the fingerprint first) and
is submitted again, restricted to the workers that are not left out (loosely: if none of
them is there any more, the scheduler may pick any, and the refusal that comes back ends the
render).
"""

from __future__ import annotations

import re

from rtcli.cluster.software import OtherSoftware, fingerprint, mismatch
from rtcli.errors import RtcliError

TRIES = 4                         # times a task is submitted, at most, when workers refuse it
WRAPPED = re.compile(r"(\w+)\((['\"])(.*)\2\)", re.S)      # a worker's error, as text: Name('message')


def survey(client) -> dict:
    """{worker address: why it cannot take this client's tasks (an RtcliError naming it), or None},
    for every worker of the cluster now. A worker that could not be asked (gone, unreachable) is
    not judged."""
    ours, found = fingerprint(), client.run(fingerprint, on_error="return")
    judged = {}
    for address, theirs in sorted(found.items()):
        if isinstance(theirs, dict):
            judged[address] = mismatch(ours, theirs, address)
        elif isinstance(theirs, (OSError, TimeoutError)):
            continue
        else:
            judged[address] = cannot_run(address, theirs)
    return judged


def cannot_run(address: str, what) -> RtcliError:
    """The refusal of a worker where rtcli's `fingerprint` failed with `what` (or gave no dict)."""
    if not isinstance(what, BaseException):
        why = f"it answered {type(what).__name__}"
    elif type(what) is Exception and (wrapped := WRAPPED.fullmatch(str(what))):    # as Client.run gives it
        why = f"{wrapped[1]}: {wrapped[3]}"
    else:
        why = f"{type(what).__name__}: {what}"
    why = " ".join(why.split())
    return RtcliError(f"the worker {address} cannot run rtcli ({why}); install the same rtcli and libraries "
                      "on every worker")


class LeftOut:
    """The workers left out of a session ({address: why}), each named once in `notes`."""

    def __init__(self, client, notes):
        self.client, self.notes, self.workers = client, notes, {}

    def add(self, refusals: dict) -> list[str]:
        """Leave out the workers of `refusals` ({address: RtcliError or None}) that are not yet; the
        addresses newly left out."""
        new = [address for address, why in sorted(refusals.items()) if why is not None and address not in self.workers]
        for address in new:
            self.workers[address] = refusals[address]
            self.notes(f"{refusals[address]} (left out: the other workers take its tasks)")
        return new

    def usable(self) -> list[str]:
        """The workers of the cluster now that are not left out."""
        return sorted(set(self.client.nthreads()) - set(self.workers))

    def refusal(self, error) -> tuple[dict, bool]:
        """({address: refusal} newly found, whether `error` was a refusal): a task's error from a worker
        that refused it, else the workers found now that would refuse."""
        if isinstance(error, OtherSoftware):
            return {error.worker: error}, True
        if not self.client.nthreads():
            return {}, False
        try:
            return {a: why for a, why in survey(self.client).items() if a not in self.workers}, False
        except Exception:                 # the cluster cannot be asked: the task's error is told as it is
            return {}, False

    def again(self, error, tries: int) -> list[str] | None:
        """The workers a failed task may run on next, or None when it must not run again: it
        failed by itself (no worker refused it, none was found that would) or was refused TRIES
        times, or no worker that runs this rtcli is left."""
        found, refused = self.refusal(error)
        new = self.add(found)
        if not (refused or new) or tries >= TRIES:
            return None
        return self.usable() or None
