"""Pure decoders: bytes from a remote in, button presses out. No I/O, no threads, no clock.

Both decoders are fed whatever the device delivered and return only presses they can prove:
anything malformed is dropped with a logged reason, and a button is never produced unless its
exact frame (serial) or its report pattern (HID) arrived.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from typing import NamedTuple

from basis import record
from kiosk.remote.buttons import Button

log = logging.getLogger("kiosk.remote")

#: bytes stripped from both ends of a serial line: CR of CRLF devices, padding spaces and tabs
_LINE_PADDING = b" \t\r"


class Press(NamedTuple):
    """One decoded button press and the raw frame it came from (for the session log)."""

    button: Button
    frame: str


class LineDecoder:
    """Frames a serial byte stream into lines (``BTN 3\\n``) and maps each line to a button.

    Lines may arrive split across any number of reads. A line that is not valid UTF-8, is longer
    than ``max_line`` bytes, or is not one of ``lines`` is dropped with a reason; decoding resumes
    at the next newline, so junk never merges into the following frame. Blank lines are ignored
    (some boxes send them as keep-alives).
    """

    def __init__(
        self,
        lines: Mapping[str, Button],
        *,
        max_line: int = 64,
        label: str = "serial",
        on_drop: Callable[[str], None] | None = None,
    ) -> None:
        self._lines = dict(lines)
        self._max_line = max_line
        self._label = label
        self._on_drop = on_drop or (lambda reason: log.warning("%s: %s", self._label, reason))
        self._buffer = bytearray()
        # True after an over-long line was dropped: skip everything up to the next newline
        self._discarding = False

    def feed(self, chunk: bytes) -> list[Press]:
        """Consume the next bytes read from the device; return the presses completed by them."""
        presses: list[Press] = []
        start = 0
        while (newline := chunk.find(b"\n", start)) >= 0:
            piece = chunk[start:newline]
            start = newline + 1
            if self._discarding:
                self._discarding = False
                continue
            self._buffer += piece
            line = bytes(self._buffer)
            self._buffer.clear()
            press = self._decode_line(line)
            if press is not None:
                presses.append(press)
        if not self._discarding:
            self._buffer += chunk[start:]
            if len(self._buffer) > self._max_line:
                self._on_drop(f"dropped a line longer than {self._max_line} bytes")
                self._buffer.clear()
                self._discarding = True
        return presses

    def _decode_line(self, line: bytes) -> Press | None:
        if len(line) > self._max_line:
            self._on_drop(f"dropped a line longer than {self._max_line} bytes")
            return None
        line = line.strip(_LINE_PADDING)
        if not line:
            return None
        try:
            text = line.decode("utf-8")
        except UnicodeDecodeError:
            self._on_drop(f"dropped a line that is not UTF-8: {line!r}")
            return None
        button = self._lines.get(text)
        if button is None:
            self._on_drop(f"dropped unknown line {text!r}")
            return None
        return Press(button, text)


@record
class ReportMatch:
    """When a HID input report shows a button held: ``report[byte]`` has all bits of ``mask``
    set, or equals ``value`` (for remotes that send one key code per report). Exactly one of
    ``mask`` and ``value`` is given."""

    byte: int
    mask: int | None = None
    value: int | None = None

    def __post_init__(self) -> None:
        if (self.mask is None) == (self.value is None):
            raise ValueError("a report match has exactly one of mask and value")

    def held(self, report: bytes) -> bool:
        """Whether the button is held in ``report`` (which must be long enough)."""
        byte = report[self.byte]
        if self.mask is not None:
            return byte & self.mask == self.mask
        return byte == self.value


class ReportDecoder:
    """Turns a HID remote's input reports into presses: one press per push, however long held.

    HID remotes report the *state* of their buttons, repeatedly while held. A press is the edge
    from not held to held; an edge less than ``debounce`` seconds after the button's previous
    edge is contact bounce and produces nothing. Reports with another report id, or too short to
    hold the mapped bytes, are unknown: ignored (logged) without changing any button's state.
    """

    def __init__(
        self,
        buttons: Mapping[Button, ReportMatch],
        *,
        report_id: int | None = None,
        debounce: float = 0.03,
        label: str = "hid",
        on_drop: Callable[[str], None] | None = None,
    ) -> None:
        self._buttons = dict(buttons)
        self._report_id = report_id
        self._debounce = debounce
        self._label = label
        self._on_drop = on_drop or (lambda reason: log.info("%s: %s", self._label, reason))
        self._needed = 1 + max((m.byte for m in self._buttons.values()), default=0)
        self._held: dict[Button, bool] = {}
        self._last_edge: dict[Button, float] = {}

    def feed(self, report: bytes, now: float) -> list[Press]:
        """Consume one input report received at time ``now`` (seconds); return new presses."""
        if self._report_id is not None and (not report or report[0] != self._report_id):
            self._on_drop(f"ignored a report with another report id: {report.hex(' ')}")
            return []
        if len(report) < self._needed:
            self._on_drop(f"ignored a {len(report)}-byte report, need {self._needed}: {report.hex(' ')}")
            return []
        presses: list[Press] = []
        for button, match in self._buttons.items():
            held = match.held(report)
            if held == self._held.get(button, False):
                continue
            self._held[button] = held
            previous = self._last_edge.get(button)
            self._last_edge[button] = now
            if held and (previous is None or now - previous >= self._debounce):
                presses.append(Press(button, report.hex(" ")))
        return presses
