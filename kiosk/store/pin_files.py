"""The clinician PIN's failure count on disk: :class:`PinFiles` is the data directory's side of
:class:`kiosk.core.pin.PinGuard`'s :class:`~kiosk.core.pin.PinCount` port.

The count is a 0600 JSON file (:data:`STATE_FILE`), rewritten whole and renamed into place so a
reader sees the old count or the new one; every process on one data directory reads, checks and
updates it under one exclusive ``flock`` (:data:`LOCK_FILE`), so two processes together get no more
guesses than one. Failures and lockouts are appended to :data:`LOG_FILE` (one JSON object a line).
The file handling lives here, not in the core, because the core does no I/O.

Nothing here raises :class:`OSError`: a full disk must not keep staff out. What cannot be opened or
written is reported to the caller (no lock, not saved) and goes to the Python log.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import logging
import os
from collections.abc import Iterator
from pathlib import Path

from fileio.bounded import BadFile, load_json, open_private, read_text
from kiosk.core.pin import DamagedCount

STATE_FILE = "pin_lockout.json"
#: held (flock, exclusive) while a process reads, checks and rewrites the count
LOCK_FILE = "pin_lockout.lock"
LOG_FILE = "security.log"

log = logging.getLogger(__name__)


class PinFiles:
    """The failure count, its lock and the security log in ``data_dir`` (made 0700 when missing)."""

    def __init__(self, data_dir: Path | str) -> None:
        self.dir = Path(data_dir)

    @contextlib.contextmanager
    def held(self) -> Iterator[bool]:
        """Hold the data directory's PIN lock; yields False when no lock can be had (disk full)."""
        try:
            self.dir.mkdir(mode=0o700, parents=True, exist_ok=True)
            descriptor = os.open(self.dir / LOCK_FILE, os.O_RDWR | os.O_CREAT, 0o600)
        except OSError as error:
            log.warning("PIN lock file %s cannot be opened (%s); counting failures in memory", LOCK_FILE, error)
            yield False
            return
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX)
            yield True
        finally:
            os.close(descriptor)  # closing releases the lock

    def load(self) -> tuple[int, float] | None:
        """The stored ``(failures, not_before)``, or None when nothing is stored; raises
        :class:`~kiosk.core.pin.DamagedCount` when the file cannot be read as a count."""
        if not (self.dir / STATE_FILE).exists():
            return None
        try:
            state = load_json(read_text(self.dir / STATE_FILE, 4096), STATE_FILE)
            return int(state["failures"]), float(state["not_before"])
        except (BadFile, KeyError, TypeError, ValueError) as error:
            raise DamagedCount(str(error)) from error

    def save(self, failures: int, not_before: float) -> bool:
        """Write the count; False (and a warning in the Python log) when it cannot be written."""
        temporary = self.dir / f".{STATE_FILE}.{os.getpid()}"
        try:
            self.dir.mkdir(mode=0o700, parents=True, exist_ok=True)
            with open_private(temporary) as handle:
                json.dump({"failures": failures, "not_before": not_before}, handle)
            os.replace(temporary, self.dir / STATE_FILE)  # never half-written: a reader sees old or new
        except OSError as error:
            with contextlib.suppress(OSError):
                temporary.unlink(missing_ok=True)
            log.warning(
                "PIN failure count (%d) cannot be written to %s (%s); counting in memory", failures, STATE_FILE, error
            )
            return False
        return True

    def append_log(self, line: str) -> None:
        """Append one line to the security log; where it cannot be written it goes to the Python log."""
        try:
            self.dir.mkdir(mode=0o700, parents=True, exist_ok=True)
            descriptor = os.open(self.dir / LOG_FILE, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)
            with os.fdopen(descriptor, "a", encoding="utf-8") as handle:
                handle.write(line + "\n")
        except OSError as error:  # a full disk must not keep staff out
            log.warning("%s cannot be written (%s): %s", LOG_FILE, error, line)
