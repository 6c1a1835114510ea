"""Test helpers: a simulated serial button box on a real pty pair, and a sink to wait on."""

from __future__ import annotations

import fcntl
import os
import queue
import struct
import termios
import threading
import tty
from pathlib import Path

from kiosk.core.channels import ChannelInput, ChannelState, ChannelStatus

#: how long a test waits for a real thread to react before failing (never reached when working)
PATIENCE = 10.0


class ButtonBox:
    """A serial button box: the kiosk opens ``link`` (a symlink to a pty slave), the box writes
    on the master side. Unplugging closes the pty and removes the link, like a USB adapter does."""

    def __init__(self, link: Path) -> None:
        self.link = link
        self.master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no line discipline between the box and the kiosk
        #: the pty slave's real path, the device node the kiosk opens through the link
        self.slave_name = os.ttyname(self._slave)
        link.symlink_to(self.slave_name)

    def write(self, data: bytes) -> None:
        """Send bytes as the box's firmware would."""
        os.write(self.master, data)

    def write_and_wait_read(self, data: bytes) -> None:
        """Send bytes and wait until the reader has taken them, so the next write is a new read.

        The kernel hands bytes from the master to the slave's queue a moment after the write, so
        an empty queue only means "read" once it has stayed empty for a few polls.
        """
        self.write(data)
        pause = threading.Event()
        empty_polls, polls = 0, 0
        while empty_polls < 4 and polls < PATIENCE / 0.005:
            pause.wait(0.005)
            polls += 1
            empty_polls = empty_polls + 1 if not self.unread() else 0
        assert empty_polls >= 4, "the reader did not read the port"

    def unread(self) -> int:
        """Bytes written by the box and not yet read by the kiosk."""
        return struct.unpack("i", fcntl.ioctl(self._slave, termios.FIONREAD, b"\0" * 4))[0]

    def unplug(self) -> None:
        """Vanish: the device node goes and reads on it fail."""
        self.link.unlink()
        os.close(self.master)
        os.close(self._slave)


class Collector:
    """A sink that records everything a source delivers, for a test to wait on."""

    def __init__(self) -> None:
        self._queue: queue.Queue = queue.Queue()
        self.received: list[ChannelInput | ChannelStatus] = []

    def __call__(self, item: ChannelInput | ChannelStatus) -> None:
        self._queue.put(item)

    def next(self) -> ChannelInput | ChannelStatus:
        """The next item, waiting for it; fails the test if none comes."""
        try:
            item = self._queue.get(timeout=PATIENCE)
        except queue.Empty:
            raise AssertionError(f"nothing arrived; so far: {self.received}") from None
        self.received.append(item)
        return item

    def status(self, state: ChannelState) -> ChannelStatus:
        """Wait for the next item, which must be a status with ``state``."""
        item = self.next()
        assert isinstance(item, ChannelStatus) and item.state == state, f"expected {state}, got {item}"
        return item

    def status_any(self) -> ChannelStatus:
        """Wait for the next item, which must be a status."""
        item = self.next()
        assert isinstance(item, ChannelStatus), f"expected a status, got {item}"
        return item

    def inputs(self, count: int) -> list[ChannelInput]:
        """Wait for the next ``count`` items, which must all be inputs."""
        items = [self.next() for _ in range(count)]
        assert all(isinstance(i, ChannelInput) for i in items), items
        return items

    def pending(self) -> list:
        """Items delivered and not yet taken (does not wait)."""
        items = []
        while not self._queue.empty():
            items.append(self._queue.get_nowait())
        self.received += items
        return items
