"""An in-process HID device behind kiosk.remote.hid's device interface.

There is no HID remote on the build machines, so this is the one stand-in the remote tests use:
it replaces only hidapi's enumerate/open/read/close; decoding, debounce and the reconnect loop
run for real on top of it.
"""

from __future__ import annotations

import queue
import threading

from kiosk.remote.hid import HidDeviceInfo


class SimulatedClock:
    """Seconds as the reports say they happened: each report read sets the time."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


class FakeHidDevice:
    """A plugged-in HID remote whose reports the test sends with the time they happen at."""

    def __init__(self, info: HidDeviceInfo, clock: SimulatedClock) -> None:
        self.info = info
        self._clock = clock
        self._reports: queue.Queue = queue.Queue()
        self.gone = threading.Event()
        self.closed = threading.Event()

    def send(self, report: bytes, at: float) -> None:
        """The remote sends ``report`` at simulated time ``at``."""
        self._reports.put((report, at))

    def read(self, timeout: float) -> bytes:
        if self.gone.is_set():
            raise OSError("read error")
        try:
            report, at = self._reports.get(timeout=timeout)
        except queue.Empty:
            return b""
        self._clock.now = at
        return report

    def close(self) -> None:
        self.closed.set()


class FakeHidBackend:
    """The USB bus: devices are plugged in and out by the test."""

    def __init__(self) -> None:
        self.clock = SimulatedClock()
        self._plugged: dict[bytes, FakeHidDevice] = {}
        self.refuse_open = False

    def plug(self, vendor_id: int, product_id: int, path: bytes = b"/dev/hidraw0") -> FakeHidDevice:
        """Plug in a remote with these ids."""
        device = FakeHidDevice(HidDeviceInfo(path, vendor_id, product_id, product="Test box"), self.clock)
        self._plugged[path] = device
        return device

    def unplug(self, device: FakeHidDevice) -> None:
        """Pull it out: it leaves the bus and its reads fail."""
        del self._plugged[device.info.path]
        device.gone.set()

    def enumerate(self, vendor_id: int = 0, product_id: int = 0) -> list[HidDeviceInfo]:
        return [
            d.info
            for d in self._plugged.values()
            if vendor_id in (0, d.info.vendor_id) and product_id in (0, d.info.product_id)
        ]

    def open(self, info: HidDeviceInfo) -> FakeHidDevice:
        if self.refuse_open:
            raise OSError("open failed")
        return self._plugged[info.path]


class SteppedWait:
    """A reconnect wait the test steps by hand: records each backoff delay, then blocks until
    :meth:`proceed` (or the reader stops). Nothing sleeps for the delay itself."""

    def __init__(self) -> None:
        self.delays: queue.Queue = queue.Queue()
        self._go = threading.Semaphore(0)

    def __call__(self, delay: float, stopping: threading.Event) -> None:
        self.delays.put(delay)
        while not stopping.is_set() and not self._go.acquire(timeout=0.05):
            pass

    def next_delay(self) -> float:
        """The delay the reader asked for next (waits for it to ask)."""
        return self.delays.get(timeout=10)

    def proceed(self) -> None:
        """Let the reader make its next attempt."""
        self._go.release()
