"""Who holds a session: one running kiosk process at a time.

A lease names its owner by host, process id and a random token drawn when the kiosk opened its
database (a process id alone can be reused by another process). The owner renews it while it
runs and releases it on exit. It lapses when its owner is gone: the process no longer exists on
this host, or the lease was not renewed for ``ttl_s`` seconds (a frozen process, another host).
The rows live in the ``leases`` table; :class:`kiosk.store.database.Store` takes and checks them inside
its write transactions, which makes taking one atomic.
"""

from __future__ import annotations

import os
import secrets
import socket
from dataclasses import field

from basis import record
from basis.errors import KioskError

#: a lease not renewed for this long has lapsed; the kiosk renews every third of it
LEASE_TTL_S = 30.0


class SessionTaken(KioskError, RuntimeError):
    """The session is held by another running kiosk (or was taken over from this one)."""


@record
class Owner:
    """A running kiosk process."""

    host: str = field(default_factory=socket.gethostname)
    pid: int = field(default_factory=os.getpid)
    token: str = field(default_factory=lambda: secrets.token_hex(8))

    def describe(self) -> str:
        """Where it runs, for staff: "ward3 (process 4242)"."""
        return f"{self.host} (process {self.pid})"


def process_exists(pid: int) -> bool:
    """Whether a process with this id runs on this host (a zombie, killed but not yet reaped by its
    parent, does not count: it will never renew anything)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # someone else's process: it exists
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as stat:
            return stat.read().rpartition(")")[2].split()[0] != "Z"
    except (OSError, IndexError):
        return True  # no /proc here: kill(0) said it exists


def lapsed(holder: Owner, renewed_at: float, now: float, ttl_s: float, me: Owner) -> str | None:
    """Why the lease held by ``holder`` has lapsed (a sentence for staff), or None if it holds."""
    if holder.host == me.host and holder.pid != me.pid and not process_exists(holder.pid):
        return f"its kiosk {holder.describe()} stopped"
    if holder.host == me.host and holder.pid == me.pid and holder.token != me.token:
        return f"its kiosk {holder.describe()} stopped"  # this process's id, reused after it ended
    if now - renewed_at > ttl_s:
        return f"its kiosk {holder.describe()} stopped answering"
    return None
