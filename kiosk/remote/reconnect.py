"""The reader thread shared by the serial and HID remotes: connect, read, report, reconnect.

A remote may be missing when the kiosk starts, be unplugged mid-session and come back. The
reader reports each change of state once (``OFF``/``CONNECTING`` while nothing usable was ever
found, ``ON`` with the device, ``LOST`` from the moment it went away until it is back) and keeps
trying with exponential backoff. The session carries on with the other channels meanwhile.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterator
from typing import Protocol

from basis import record
from basis.errors import KioskError
from kiosk.core.channels import Channel, ChannelState, ChannelStatus, Sink
from kiosk.remote.buttons import to_input
from kiosk.remote.decoders import Press

log = logging.getLogger("kiosk.remote")

#: waits ``delay`` seconds or until the event is set (the reader is stopping); tests inject
#: their own to step the reconnect loop without sleeping
Wait = Callable[[float, threading.Event], object]


def wait_or_stop(delay: float, stopping: threading.Event) -> None:
    """The real :data:`Wait`: sleep ``delay`` seconds, waking at once when the reader stops."""
    stopping.wait(delay)


@record
class Backoff:
    """Delays between reconnect attempts: ``initial``, then times ``factor``, at most ``maximum``."""

    initial: float = 0.5
    factor: float = 2.0
    maximum: float = 10.0

    def delays(self) -> Iterator[float]:
        """A fresh, endless sequence of delays (restarted after every successful connection)."""
        delay = self.initial
        while True:
            yield delay
            delay = min(delay * self.factor, self.maximum)


class DeviceUnavailable(KioskError):
    """Connecting failed. ``state`` is OFF when no device is there, CONNECTING when one is there
    but cannot be opened yet (busy, permissions); ``reason`` is one sentence for the clinician."""

    def __init__(self, state: ChannelState, reason: str) -> None:
        super().__init__(reason)
        self.state = state
        self.reason = reason


class DeviceLost(KioskError):
    """The open device went away (read error, port gone); the message is the reason."""


class Connection(Protocol):
    """An open remote: reads presses until it raises :class:`DeviceLost`."""

    #: e.g. "serial /dev/ttyUSB0"; prefixed to each press's detail
    label: str
    #: shown with the ON status, e.g. "connected to /dev/ttyUSB0 (profile serial-usb)"
    description: str

    def read(self) -> list[Press]:
        """Wait briefly for input; return the completed presses (often none)."""

    def close(self) -> None:
        """Release the device; never raises."""


class ReconnectingReader:
    """Runs a remote in a daemon thread and hands presses and status changes to a sink.

    Subclasses provide :meth:`connect`. Implements the :class:`~kiosk.core.channels.InputSource`
    protocol.
    """

    def __init__(self, name: str, *, backoff: Backoff | None = None, wait: Wait = wait_or_stop) -> None:
        self.name = name
        self._backoff = backoff or Backoff()
        self._wait = wait
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None
        self._state: ChannelState | None = None

    def connect(self) -> Connection:
        """Find and open the device, or raise :class:`DeviceUnavailable`."""
        raise NotImplementedError

    def start(self, sink: Sink) -> None:
        """Start the reader thread; returns at once."""
        if self._thread is not None:
            raise RuntimeError(f"{self.name} was already started")
        self._thread = threading.Thread(target=self._run, args=(sink,), name=self.name, daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop the thread and close the device; safe to call twice."""
        self._stopping.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5)

    def _run(self, sink: Sink) -> None:
        delays = self._backoff.delays()
        was_connected = False
        while not self._stopping.is_set():
            try:
                connection = self.connect()
            except DeviceUnavailable as missing:
                self._report(sink, ChannelState.LOST if was_connected else missing.state, missing.reason)
            except Exception as error:  # drivers also fail in undocumented ways: log it, retry
                log.exception("%s: unexpected error while connecting", self.name)
                self._report(
                    sink,
                    ChannelState.LOST if was_connected else ChannelState.CONNECTING,
                    f"cannot open the remote: {error}",
                )
            else:
                was_connected = True
                if self._read_until_lost(sink, connection):
                    delays = self._backoff.delays()
            self._wait(next(delays), self._stopping)

    def _read_until_lost(self, sink: Sink, connection: Connection) -> bool:
        """Deliver presses until the device fails or the reader stops; report the loss.

        Returns whether the device ever read successfully: only then does the backoff start
        over, so a device that opens but fails at once is retried ever more slowly.
        """
        self._report(sink, ChannelState.ON, connection.description)
        healthy = False
        reason = ""
        try:
            while not self._stopping.is_set():
                presses = connection.read()
                healthy = True
                for press in presses:
                    self._deliver(sink, to_input(press.button, f"{connection.label}: {press.frame}"))
        except DeviceLost as lost:
            reason = str(lost)
        except Exception as error:  # as above: a broken driver must not silently end the reader
            log.exception("%s: unexpected error while reading", self.name)
            reason = f"the remote failed: {error}"
        finally:
            connection.close()
        if reason:
            self._report(sink, ChannelState.LOST, reason)
        return healthy

    def _report(self, sink: Sink, state: ChannelState, reason: str) -> None:
        # one status per change of state: retries while a device stays away are not news
        if state == self._state:
            return
        self._state = state
        log.info("%s: %s (%s)", self.name, state.value, reason)
        self._deliver(sink, ChannelStatus(Channel.REMOTE, state, source=self.name, reason=reason))

    def _deliver(self, sink: Sink, item) -> None:
        try:
            sink(item)
        except Exception:  # a faulty sink must not kill the remote; the press is logged
            log.exception("%s: the sink failed on %r", self.name, item)
