"""USB HID big-button remotes (hidapi): enumerate, open, read reports in a thread, debounce.

hidapi sits behind a two-method device interface (:class:`HidBackend` to enumerate and open,
:class:`HidDevice` to read and close) so the reader, decoder and reconnect loop run the same
against the real library and, in tests on machines without a HID remote, an in-process device.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Protocol

from basis import record
from kiosk.core.channels import ChannelState
from kiosk.remote.decoders import Press, ReportDecoder
from kiosk.remote.profiles import HidProfile, usb_id
from kiosk.remote.reconnect import Backoff, DeviceLost, DeviceUnavailable, ReconnectingReader, Wait, wait_or_stop

#: how long one read waits for a report; bounds how quickly stop() is noticed
READ_TIMEOUT = 0.1
#: largest input report read at once (full-speed USB interrupt packets are at most 64 bytes)
MAX_REPORT = 64


@record
class HidDeviceInfo:
    """One HID interface as enumeration reports it."""

    path: bytes
    vendor_id: int
    product_id: int
    manufacturer: str = ""
    product: str = ""
    serial_number: str = ""

    @property
    def usb_id(self) -> str:
        """The device's ids, as :func:`~kiosk.remote.profiles.usb_id` writes them."""
        return usb_id(self.vendor_id, self.product_id)


class HidDevice(Protocol):
    """An open HID device."""

    def read(self, timeout: float) -> bytes:
        """One input report, or ``b""`` if none came within ``timeout`` seconds.
        Raises OSError when the device is gone."""

    def close(self) -> None:
        """Release the device."""


class HidBackend(Protocol):
    """Finds and opens HID devices."""

    def enumerate(self, vendor_id: int = 0, product_id: int = 0) -> list[HidDeviceInfo]:
        """Connected HID interfaces, all of them or those with the given ids (0 = any)."""

    def open(self, info: HidDeviceInfo) -> HidDevice:
        """Open one enumerated interface; raises OSError if it cannot be opened."""


class HidapiDevice:
    """A device opened through hidapi (``hid.device``)."""

    def __init__(self, device) -> None:
        self._device = device

    def read(self, timeout: float) -> bytes:
        """One input report or ``b""`` on timeout; hidapi raises OSError when the device is gone."""
        return bytes(self._device.read(MAX_REPORT, max(1, int(timeout * 1000))))

    def close(self) -> None:
        """Close the hidapi handle."""
        self._device.close()


class HidapiBackend:
    """The real backend: hidapi's ``hid.enumerate`` and ``hid.device().open_path``.

    hidapi is imported on first use, so a machine without the library can still run the kiosk
    (the HID remote is then reported as off).
    """

    def enumerate(self, vendor_id: int = 0, product_id: int = 0) -> list[HidDeviceInfo]:
        """Connected HID interfaces as hidapi lists them."""
        import hid

        return [
            HidDeviceInfo(
                path=entry["path"],
                vendor_id=entry["vendor_id"],
                product_id=entry["product_id"],
                manufacturer=entry.get("manufacturer_string") or "",
                product=entry.get("product_string") or "",
                serial_number=entry.get("serial_number") or "",
            )
            for entry in hid.enumerate(vendor_id, product_id)
        ]

    def open(self, info: HidDeviceInfo) -> HidapiDevice:
        """Open ``info``'s interface by path."""
        import hid

        device = hid.device()
        device.open_path(info.path)
        return HidapiDevice(device)


class HidConnection:
    """An open HID remote: reads reports and decodes them into presses."""

    def __init__(self, info: HidDeviceInfo, device: HidDevice, profile: HidProfile, clock: Callable[[], float]) -> None:
        self.label = f"hid {info.usb_id}"
        self._usb_id = info.usb_id
        name = f" {info.product}" if info.product else ""
        self.description = f"connected to{name} {info.usb_id} (profile {profile.name})"
        self._device = device
        self._clock = clock
        self._decoder = ReportDecoder(
            profile.buttons, report_id=profile.report_id, debounce=profile.debounce_ms / 1000, label=self.label
        )

    def read(self) -> list[Press]:
        """Read one report (or time out); raise DeviceLost if the device failed."""
        try:
            report = self._device.read(READ_TIMEOUT)
        except OSError as error:
            raise DeviceLost(f"HID remote {self._usb_id} stopped working: {error}") from None
        return self._decoder.feed(report, self._clock()) if report else []

    def close(self) -> None:
        """Close the device, ignoring errors from one that is already gone."""
        try:
            self._device.close()
        except OSError:
            pass


class HidRemote(ReconnectingReader):
    """A HID remote from a :class:`HidProfile`, reconnecting by itself.

    ``clock`` (seconds, monotonic) times the debounce; ``backend`` defaults to hidapi.
    """

    def __init__(
        self,
        profile: HidProfile,
        *,
        backend: HidBackend | None = None,
        backoff: Backoff | None = None,
        wait: Wait = wait_or_stop,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__(f"hid {profile.usb_id}", backoff=backoff, wait=wait)
        self.profile = profile
        self._backend = backend or HidapiBackend()
        self._clock = clock

    def connect(self) -> HidConnection:
        """Open the first interface with the profile's ids, or raise DeviceUnavailable."""
        wanted = f"{self.profile.usb_id} ({self.profile.name})"
        try:
            found = self._backend.enumerate(self.profile.vendor_id, self.profile.product_id)
        except (ImportError, OSError) as error:
            raise DeviceUnavailable(ChannelState.OFF, f"cannot list HID devices: {error}") from None
        if not found:
            raise DeviceUnavailable(ChannelState.OFF, f"no HID remote {wanted}")
        problems = []
        for info in found:
            try:
                return HidConnection(info, self._backend.open(info), self.profile, self._clock)
            except OSError as error:
                problems.append(f"{info.path.decode(errors='replace')}: {error}")
        raise DeviceUnavailable(ChannelState.CONNECTING, f"cannot open HID remote {wanted}: " + "; ".join(problems))
