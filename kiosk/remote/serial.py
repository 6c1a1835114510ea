"""Serial big-button remotes (pyserial): a reader thread, line framing, unplug and replug.

The port is given by the profile as a path or a glob (``/dev/ttyUSB*``); on every connection
attempt the first matching port that opens is used, so a box that comes back under another
number is found again, and a port already held by another reader is skipped. Each connection gets a
fresh :class:`~kiosk.remote.decoders.LineDecoder`: half a line from an unplugged box never joins the
first line of the next one.
"""

from __future__ import annotations

import glob
import os
from typing import TYPE_CHECKING

from kiosk.core.channels import ChannelState
from kiosk.remote.decoders import LineDecoder, Press
from kiosk.remote.profiles import SerialProfile
from kiosk.remote.reconnect import Backoff, DeviceLost, DeviceUnavailable, ReconnectingReader, Wait, wait_or_stop

if TYPE_CHECKING:
    import serial

#: how long one read waits for bytes; bounds how quickly stop() and a vanished port are noticed
READ_TIMEOUT = 0.1


def matching_ports(pattern: str) -> list[str]:
    """Ports matching a profile's path or glob (checked by the profile's loader: under /dev, no
    '**'), in a stable order."""
    return sorted(glob.glob(pattern, recursive=False))


class SerialConnection:
    """An open serial remote: reads bytes and decodes them into presses."""

    def __init__(self, port: str, device: serial.Serial, profile: SerialProfile) -> None:
        self.label = f"serial {port}"
        self.description = f"connected to {port} (profile {profile.name})"
        self._port = port
        self._device = device
        self._decoder = LineDecoder(profile.lines, max_line=profile.max_line, label=self.label)

    def read(self) -> list[Press]:
        """Read what arrived within :data:`READ_TIMEOUT`; raise DeviceLost if the port failed."""
        import serial  # pyserial loads on the reader's thread, after the welcome is drawn

        try:
            data = self._device.read(max(1, self._device.in_waiting))
        except (serial.SerialException, OSError) as error:
            raise DeviceLost(f"{self._port} stopped working: {error}") from None
        # some drivers just go quiet when unplugged; the vanished device node tells
        if not data and not os.path.exists(self._port):
            raise DeviceLost(f"{self._port} was unplugged")
        return self._decoder.feed(data)

    def close(self) -> None:
        """Close the port, ignoring errors from a device that is already gone."""
        import serial

        try:
            self._device.close()
        except (serial.SerialException, OSError):
            pass


class SerialRemote(ReconnectingReader):
    """A serial remote from a :class:`SerialProfile`, reconnecting by itself."""

    def __init__(self, profile: SerialProfile, *, backoff: Backoff | None = None, wait: Wait = wait_or_stop) -> None:
        super().__init__(f"serial {profile.port}", backoff=backoff, wait=wait)
        self.profile = profile

    def connect(self) -> SerialConnection:
        """Open the first matching port, or raise DeviceUnavailable saying why none could be."""
        import serial

        ports = matching_ports(self.profile.port)
        if not ports:
            raise DeviceUnavailable(ChannelState.OFF, f"no serial remote on {self.profile.port}")
        problems = []
        for port in ports:
            try:
                # exclusive: a second reader on the same port would split one press between two
                device = serial.Serial(port, baudrate=self.profile.baud, timeout=READ_TIMEOUT, exclusive=True)
            except (serial.SerialException, OSError, ValueError) as error:
                problems.append(f"{port}: {error}")
                continue
            return SerialConnection(port, device, self.profile)
        raise DeviceUnavailable(ChannelState.CONNECTING, "cannot open " + "; ".join(problems))
