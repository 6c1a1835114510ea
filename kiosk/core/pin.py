"""The clinician PIN: stored as a salted scrypt hash, guarded by a growing delay and a lockout.

The configuration holds ``clinician_pin_hash`` (written by `kiosk pin set`); a legacy plain
``clinician_pin`` still works, with a warning. Failed attempts are counted through a
:class:`PinCount` (a 0600 file of the data directory: :mod:`kiosk.store.pin_files`), so killing
and restarting the kiosk does not reset them, and every failure and lockout is appended to the
security log beside it (one JSON object a line).

After :data:`FREE_FAILURES` wrong PINs in a row each further attempt must wait, twice as long each
time (:data:`FIRST_DELAY_S`, doubling, at most :data:`MAX_DELAY_S`); after :data:`LOCKOUT_FAILURES`
the PIN pad is locked for :data:`LOCKOUT_S`. A right PIN clears the count. Through the served page
this turns 12 guesses a second into about 20 guesses an hour.

The count is the data directory's, not the process's: every kiosk process on one data directory (a
`kiosk run` and the served page's `kiosk serve` sessions) reads, checks and updates it under one
exclusive lock (:meth:`PinCount.held`), so two processes together get no more guesses than one.

When the count cannot be written (a full disk) the process keeps counting in memory, never below
what the file says, and a right PIN still lets staff in: the out-of-order screen sends them to the
clinician screen to see why. What could not be written goes to the Python log.
The core decides; the file lock and the file I/O are the store's.
"""

from __future__ import annotations

import base64
import contextlib
import hashlib
import hmac
import json
import math
import secrets
import time
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager
from typing import Protocol

from basis import record
from basis.errors import KioskError

#: the PIN a fresh install uses; the clinician screens warn while it is unchanged
DEFAULT_PIN = "1234"
#: a PIN chosen by staff has at least this many digits (the default's 4 are a public secret anyway)
MIN_DIGITS = 6
MAX_DIGITS = 12
#: scrypt cost: about 50 ms a check here, 16 MB of memory; a stolen config costs a guesser as much
_SCRYPT = {"n": 2**14, "r": 8, "p": 1}
FREE_FAILURES = 3
FIRST_DELAY_S = 5.0
MAX_DELAY_S = 300.0
LOCKOUT_FAILURES = 10
LOCKOUT_S = 3600.0


class DamagedCount(ValueError):
    """The stored failure count cannot be read as one (the guard then locks the pad)."""


class PinCount(Protocol):
    """Where the failure count is shared between the processes of one data directory, and where
    the security log goes: the port through which the core, which does no I/O, keeps them
    (:class:`kiosk.store.pin_files.PinFiles` on disk). None of these raises :class:`OSError`."""

    def held(self) -> AbstractContextManager[bool]:
        """Hold the shared lock while the block runs; it gives False when no lock can be had."""
        ...

    def load(self) -> tuple[int, float] | None:
        """The stored ``(failures, not_before)``, None when nothing is stored; raises
        :class:`DamagedCount` when what is stored is not a count."""
        ...

    def save(self, failures: int, not_before: float) -> bool:
        """Store the count; False when it could not be stored."""
        ...

    def append_log(self, line: str) -> None:
        """Append one JSON line to the security log (best effort)."""
        ...


class PinError(KioskError, ValueError):
    """A PIN or a stored hash is unusable; the message says why in one sentence."""


def pin_problem(pin: str) -> str | None:
    """Why ``pin`` cannot be a new clinician PIN, or None."""
    if not pin.isascii() or not pin.isdigit():
        return "a PIN is digits only"
    if not MIN_DIGITS <= len(pin) <= MAX_DIGITS:
        return f"a PIN has {MIN_DIGITS} to {MAX_DIGITS} digits"
    if pin == DEFAULT_PIN or len(set(pin)) == 1:
        return "choose a PIN that is not the default or one digit repeated"
    return None


def hash_pin(pin: str) -> str:
    """``scrypt$n$r$p$salt$hash`` (base64) of a PIN that :func:`pin_problem` accepts."""
    if (problem := pin_problem(pin)) is not None:
        raise PinError(problem)
    salt = secrets.token_bytes(16)
    digest = hashlib.scrypt(pin.encode(), salt=salt, **_SCRYPT, dklen=32)
    encode = base64.b64encode
    return f"scrypt${_SCRYPT['n']}${_SCRYPT['r']}${_SCRYPT['p']}${encode(salt).decode()}${encode(digest).decode()}"


def hash_problem(text: str) -> str | None:
    """Why ``text`` is not a hash :func:`hash_pin` wrote, or None."""
    try:
        _parse_hash(text)
    except (ValueError, TypeError):
        return "clinician_pin_hash is not a hash written by `kiosk pin set`; run it again"
    return None


def _parse_hash(text: str) -> tuple[int, int, int, bytes, bytes]:
    kind, n, r, p, salt, digest = text.split("$")
    if kind != "scrypt" or not (2 <= int(n) <= 2**20 and 1 <= int(r) <= 32 and 1 <= int(p) <= 16):
        raise ValueError(text)
    return int(n), int(r), int(p), base64.b64decode(salt, validate=True), base64.b64decode(digest, validate=True)


def matches(secret: str, pin: str) -> bool:
    """``pin`` is the PIN ``secret`` stands for: a hash from :func:`hash_pin`, or a legacy plain PIN."""
    if not secret.startswith("scrypt$"):
        return hmac.compare_digest(secret.encode(), pin.encode())
    n, r, p, salt, digest = _parse_hash(secret)
    if not pin.isascii() or len(pin) > MAX_DIGITS:
        return False
    return hmac.compare_digest(hashlib.scrypt(pin.encode(), salt=salt, n=n, r=r, p=p, dklen=len(digest)), digest)


@record
class Verdict:
    """What one attempt at the PIN pad gave."""

    ok: bool
    #: seconds before the next attempt is taken (0: now)
    wait_s: float = 0.0
    #: the pad is locked (``wait_s`` says until when)
    locked: bool = False
    #: the attempt came before the wait was over and was not checked
    early: bool = False


class PinGuard:
    """Checks PIN attempts against the configured secret, counting failures across restarts.

    ``secret`` is a hash from :func:`hash_pin` or a legacy plain PIN. ``count`` keeps the count
    and the security log (:class:`kiosk.store.pin_files.PinFiles` on the data directory; None: in
    memory only, for tests of the screens). ``now`` gives wall-clock seconds: the count must
    survive a restart, which a monotonic clock does not.
    """

    def __init__(self, secret: str, count: PinCount | None = None, now: Callable[[], float] = time.time) -> None:
        self.secret = secret
        self._count = count
        self._now = now
        #: the count as last read from the data directory (another process may have moved it since)
        self.failures, self.not_before = 0, 0.0
        #: the count this process could not write (disk full), kept until a write succeeds
        self._unsaved: tuple[int, float] | None = None
        with self._shared_count():
            pass

    @property
    def is_default(self) -> bool:
        """The PIN is still the public default."""
        return self.secret == DEFAULT_PIN

    @property
    def is_plain(self) -> bool:
        """The PIN is stored in plain text (legacy ``clinician_pin``)."""
        return not self.secret.startswith("scrypt$")

    @property
    def warning(self) -> str | None:
        """What staff should be told about the PIN, or None."""
        if self.is_default:
            return "The clinician PIN is still the public default 1234: run `kiosk pin set` to choose one."
        if self.is_plain:
            return "The clinician PIN is stored in plain text (clinician_pin): run `kiosk pin set` to store it hashed."
        return None

    def wait_left(self) -> float:
        """Seconds before the next attempt is checked (0: now), by the data directory's count."""
        with self._shared_count():
            return max(0.0, self.not_before - self._now())

    def attempt(self, pin: str) -> Verdict:
        """Check one attempt; a failure is counted, logged and delays the next. The whole
        read-check-write holds the data directory's lock, so attempts of other processes wait."""
        with self._shared_count():
            if (left := max(0.0, self.not_before - self._now())) > 0:
                return Verdict(False, left, locked=self.failures >= LOCKOUT_FAILURES, early=True)
            if matches(self.secret, pin):
                if self.failures:
                    self._log("pin_accepted", f"after {self.failures} failed attempts")
                self.failures, self.not_before = 0, 0.0
                self._save()
                return Verdict(True)
            self.failures += 1
            delay = self._delay(self.failures)
            self.not_before = self._now() + delay
            self._save()
            locked = self.failures >= LOCKOUT_FAILURES
            self._log("pin_failed", f"failure {self.failures} in a row; next attempt in {delay:g} s")
            if locked:
                self._log("pin_locked", f"{self.failures} failures in a row: the PIN pad is locked for {delay:g} s")
            return Verdict(False, delay, locked=locked)

    @contextlib.contextmanager
    def _shared_count(self) -> Iterator[None]:
        """Hold the shared count's lock and read the count into ``failures``/``not_before``
        (in memory only without a :class:`PinCount`, or when no lock can be had)."""
        if self._count is None:
            yield
            return
        with self._count.held() as held:
            if not held:  # no lock to be had (disk full): this process's count alone
                if self._unsaved is not None:
                    self.failures, self.not_before = self._unsaved
                yield
                return
            self.failures, self.not_before = self._load()
            if self._unsaved is not None:  # what this process counted and could not write still holds
                self.failures = max(self.failures, self._unsaved[0])
                self.not_before = max(self.not_before, self._unsaved[1])
            yield

    @staticmethod
    def _delay(failures: int) -> float:
        if failures >= LOCKOUT_FAILURES:
            return LOCKOUT_S
        if failures < FREE_FAILURES:
            return 0.0
        return min(FIRST_DELAY_S * 2 ** (failures - FREE_FAILURES), MAX_DELAY_S)

    def _load(self) -> tuple[int, float]:
        if self._count is None:
            return 0, 0.0
        try:
            stored = self._count.load()
        except DamagedCount:
            # a damaged count must not open the pad: treat it as a lockout starting now, written
            # back so that every process (and every later read) sees the same lockout
            self._log("pin_state_damaged", "the failure count could not be read; locking the PIN pad")
            self.failures, self.not_before = LOCKOUT_FAILURES, self._now() + LOCKOUT_S
            self._save()
            return self.failures, self.not_before
        if stored is None:
            return 0, 0.0
        failures, not_before = stored
        # a clock set back must not shorten a lockout by more than its own length
        return max(0, failures), min(not_before, self._now() + LOCKOUT_S)

    def _save(self) -> None:
        """Write the count; when it cannot be written it is kept in memory."""
        if self._count is None:
            return
        saved = self._count.save(self.failures, self.not_before)
        self._unsaved = None if saved else (self.failures, self.not_before)

    def _log(self, event: str, detail: str) -> None:
        if self._count is None:
            return
        at = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(self._now()))
        self._count.append_log(json.dumps({"at": at, "event": event, "detail": detail}))


#: staff open the PIN pad by touch alone: this many taps in the top-left corner of a patient screen,
#: each within TAP_GAP_S of the previous (a patient resting a hand there does not tap five times)
CORNER_TAPS = 5
TAP_GAP_S = 1.5
#: the corner, in cells from the top-left: the title of the top bar, which holds no control
CORNER_CELLS = (10, 3)


class CornerTaps:
    """Counts taps in the staff corner; :meth:`tap` says when the pattern is complete."""

    def __init__(self, now: Callable[[], float] = time.monotonic) -> None:
        self._now = now
        self._count = 0
        self._last = -math.inf

    def tap(self, x: int, y: int) -> bool:
        """A tap at cell (x, y) of the screen; True when it completes the pattern."""
        now = self._now()
        if not (0 <= x < CORNER_CELLS[0] and 0 <= y < CORNER_CELLS[1]):
            self._count = 0
            return False
        self._count = self._count + 1 if now - self._last <= TAP_GAP_S else 1
        self._last = now
        if self._count >= CORNER_TAPS:
            self._count = 0
            return True
        return False
