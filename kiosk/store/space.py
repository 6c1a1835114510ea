"""Whether the kiosk's data directory takes writes again (after a full disk or a failing drive)."""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

#: bytes the kiosk must be able to write beside its database before an out-of-order kiosk takes
#: patients again (a test's rows, its QoS trace and the WAL need room to grow)
PROBE_BYTES = 256 * 1024


def can_write(directory: Path) -> bool:
    """``directory`` takes :data:`PROBE_BYTES` more (written, synced and removed)."""
    probe = directory / ".kiosk-write-probe"
    try:
        handle = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        try:
            os.write(handle, bytes(PROBE_BYTES))
            os.fsync(handle)
        finally:
            os.close(handle)
        return True
    except OSError:
        return False
    finally:
        with contextlib.suppress(OSError):
            probe.unlink()
