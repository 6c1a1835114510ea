"""The HID remote: real hidapi where it runs here (enumeration), the reader, debounce and
reconnect loop through an in-process device (no HID remote exists on this machine)."""

from __future__ import annotations

import pytest

from kiosk.core.channels import Channel, ChannelInput, ChannelState, Command
from kiosk.remote.hid import HidapiBackend, HidRemote
from kiosk.remote.profiles import load_profiles
from kiosk.remote.reconnect import Backoff

from .boxes import Collector
from .fake_hid import FakeHidBackend, SteppedWait

PROFILE = load_profiles().hid[0]  # 1209:0001, report 1, one bit per button in byte 1
VID, PID = PROFILE.vendor_id, PROFILE.product_id


@pytest.fixture
def hid_bus():
    return FakeHidBackend()


@pytest.fixture
def hid_wait():
    return SteppedWait()


@pytest.fixture
def hid_reader(hid_bus, hid_wait):
    reader = HidRemote(PROFILE, backend=hid_bus, backoff=Backoff(0.5, 2, 4), wait=hid_wait, clock=hid_bus.clock)
    yield reader
    reader.stop()


def report(bits: int, extra: int = 0) -> bytes:
    return bytes([1, bits, extra])


def test_real_hidapi_enumerates_and_reports_the_remote_off():
    backend = HidapiBackend()
    assert backend.enumerate(VID, PID) == []  # no HID remote on this machine
    reader = HidRemote(PROFILE, backend=backend, backoff=Backoff(60, 1, 60))
    sink = Collector()
    reader.start(sink)
    try:
        off = sink.status(ChannelState.OFF)
    finally:
        reader.stop()
    assert off.reason == "no HID remote 1209:0001 (hid-bigbutton)" and off.source == "hid 1209:0001"


def test_held_button_and_contact_bounce_each_give_one_press(hid_bus, hid_reader):
    device = hid_bus.plug(VID, PID)
    sink = Collector()
    hid_reader.start(sink)
    assert "Test box 1209:0001" in sink.status(ChannelState.ON).reason
    for i in range(10):  # answer 2 held for half a second, reported every 50 ms
        device.send(report(0x02), at=1.0 + i * 0.05)
    device.send(report(0x00), at=1.5)
    # repeat pressed with bounce: on, off, on within 8 ms
    for at, bits in [(2.0, 0x10), (2.004, 0x00), (2.008, 0x10), (2.3, 0x00)]:
        device.send(report(bits), at=at)
    device.send(report(0x00, 0x02), at=3.0)  # volume down, in byte 2
    device.send(bytes([5, 0xFF, 0xFF]), at=3.1)  # another report id: ignored
    first, second, third = sink.inputs(3)
    assert first == ChannelInput(Channel.REMOTE, option=2, detail="hid 1209:0001: 01 02 00")
    assert second.command is Command.REPEAT and third.command is Command.VOLUME_DOWN
    device.send(report(0x08), at=4.0)
    assert sink.inputs(1)[0].option == 4  # the ignored report came and went without a press
    assert sink.pending() == []


def test_backs_off_while_absent_and_resets_after_each_connection(hid_bus, hid_wait, hid_reader):
    sink = Collector()
    hid_reader.start(sink)
    off = sink.status(ChannelState.OFF)
    assert off.reason == "no HID remote 1209:0001 (hid-bigbutton)"
    delays = [hid_wait.next_delay()]
    for _ in range(4):
        hid_wait.proceed()
        delays.append(hid_wait.next_delay())
    assert delays == [0.5, 1.0, 2.0, 4.0, 4.0]
    assert sink.pending() == []  # still off: no repeated status while nothing changes

    device = hid_bus.plug(VID, PID)  # while the reader waits
    hid_wait.proceed()
    sink.status(ChannelState.ON)
    device.send(report(0x01), at=10.0)
    assert sink.inputs(1)[0].option == 1

    hid_bus.unplug(device)
    lost = sink.status(ChannelState.LOST)
    assert "1209:0001" in lost.reason and device.closed.is_set()
    assert hid_wait.next_delay() == 0.5  # backoff starts over after a good connection
    hid_wait.proceed()
    assert hid_wait.next_delay() == 1.0
    assert sink.pending() == []  # still lost, not reported again

    device = hid_bus.plug(VID, PID, path=b"/dev/hidraw3")
    hid_wait.proceed()
    sink.status(ChannelState.ON)
    device.send(report(0x40), at=20.0)
    assert sink.inputs(1)[0].command is Command.CALL_DOCTOR


def test_a_remote_that_cannot_be_opened_is_connecting_until_it_can(hid_bus, hid_wait, hid_reader):
    hid_bus.refuse_open = True
    device = hid_bus.plug(VID, PID)
    sink = Collector()
    hid_reader.start(sink)
    connecting = sink.status(ChannelState.CONNECTING)
    assert connecting.reason == "cannot open HID remote 1209:0001 (hid-bigbutton): /dev/hidraw0: open failed"
    hid_bus.refuse_open = False
    hid_wait.next_delay()
    hid_wait.proceed()
    sink.status(ChannelState.ON)
    device.send(report(0x04), at=1.0)
    assert sink.inputs(1)[0].option == 3


def test_other_devices_on_the_bus_are_not_used(hid_bus, hid_wait, hid_reader):
    hid_bus.plug(0x046D, 0xC52B)  # somebody's mouse receiver
    sink = Collector()
    hid_reader.start(sink)
    sink.status(ChannelState.OFF)


def test_an_undocumented_driver_failure_is_reported_lost_and_the_reader_carries_on(
    hid_bus, hid_wait, hid_reader, caplog
):
    device = hid_bus.plug(VID, PID)
    sink = Collector()
    hid_reader.start(sink)
    sink.status(ChannelState.ON)

    def broken(timeout: float) -> bytes:
        raise RuntimeError("hidapi fell over")

    device.read = broken
    lost = sink.status(ChannelState.LOST)
    assert lost.reason == "the remote failed: hidapi fell over"
    assert "unexpected error while reading" in caplog.text
    assert hid_wait.next_delay() == 0.5  # it waits before trying again, even though still plugged
    hid_wait.proceed()
    sink.status(ChannelState.ON)
    sink.status(ChannelState.LOST)  # the same broken device again
    assert hid_wait.next_delay() == 1.0  # never read well, so the backoff keeps growing

    hid_bus.unplug(device)
    device = hid_bus.plug(VID, PID)  # a working one
    hid_wait.proceed()
    sink.status(ChannelState.ON)
    device.send(report(0x01), at=1.0)
    assert sink.inputs(1)[0].option == 1
