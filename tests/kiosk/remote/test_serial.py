"""The serial remote with real pyserial on a real pty pair: presses, junk, unplug and replug."""

from __future__ import annotations

import logging
import os
from dataclasses import replace

import pytest

from kiosk.core.channels import Channel, ChannelInput, ChannelState, Command
from kiosk.remote.profiles import load_profiles
from kiosk.remote.reconnect import Backoff
from kiosk.remote.serial import SerialRemote

from .boxes import ButtonBox, Collector

#: tiny delays keep the reconnect loop quick; the test itself only waits on what arrives
FAST = Backoff(initial=0.005, factor=2, maximum=0.02)


@pytest.fixture
def remote_dir(tmp_path):
    return tmp_path


@pytest.fixture
def remote_profile(remote_dir):
    builtin = load_profiles().serial[0]
    return replace(builtin, port=str(remote_dir / "ttyUSB-test*"))


@pytest.fixture
def remote_reader(remote_profile):
    reader = SerialRemote(remote_profile, backoff=FAST)
    yield reader
    reader.stop()


def open_files() -> list[str]:
    """What this process has open, by path."""
    paths = []
    for fd in os.listdir("/proc/self/fd"):
        try:
            paths.append(os.readlink(f"/proc/self/fd/{fd}"))
        except OSError:  # the fd listdir itself used is already closed
            pass
    return paths


def options(items):
    return [i.option if i.option is not None else i.command for i in items]


def test_presses_junk_and_partial_lines(remote_dir, remote_reader, caplog):
    caplog.set_level(logging.WARNING, logger="kiosk.remote")
    box = ButtonBox(remote_dir / "ttyUSB-test0")
    sink = Collector()
    remote_reader.start(sink)
    on = sink.status(ChannelState.ON)
    assert "ttyUSB-test0" in on.reason and on.channel is Channel.REMOTE
    box.write(b"BTN 1\n")
    first = sink.inputs(1)[0]
    assert first == ChannelInput(Channel.REMOTE, option=1, detail=f"serial {box.link}: BTN 1")
    box.write(b"\xff\x00garbage\nBTN 9\n" + b"#" * 200 + b"BTN 2\n")  # all junk
    box.write_and_wait_read(b"BT")  # a line split across reads
    box.write_and_wait_read(b"N ")
    box.write(b"R\r\nBTN 4\n")
    assert options(sink.inputs(2)) == [Command.REPEAT, 4]
    assert "not UTF-8" in caplog.text and "'BTN 9'" in caplog.text and "longer than 64" in caplog.text
    box.unplug()
    sink.status(ChannelState.LOST)
    assert sink.pending() == []


def test_unplug_then_replug_reports_lost_and_works_again(remote_dir, remote_reader):
    link = remote_dir / "ttyUSB-test0"
    box = ButtonBox(link)
    sink = Collector()
    remote_reader.start(sink)
    sink.status(ChannelState.ON)
    box.write(b"BTN 3\n")
    assert options(sink.inputs(1)) == [3]
    box.write_and_wait_read(b"BTN")  # half a line when the cable is pulled
    box.unplug()
    lost = sink.status(ChannelState.LOST)
    assert "ttyUSB-test0" in lost.reason

    box = ButtonBox(link)  # plugged back in: a new pty behind the same name
    sink.status(ChannelState.ON)
    box.write(b" 4\nBTN 4\n")  # the old half line must not complete into a press
    assert options(sink.inputs(1)) == [4]
    box.unplug()
    sink.status(ChannelState.LOST)
    box = ButtonBox(remote_dir / "ttyUSB-test7")  # back under another number
    sink.status(ChannelState.ON)
    box.write(b"BTN D\n")
    assert options(sink.inputs(1)) == [Command.CALL_DOCTOR]
    assert sink.pending() == []


def test_no_device_at_start_is_reported_and_found_when_plugged_in(remote_dir, remote_reader, remote_profile):
    sink = Collector()
    remote_reader.start(sink)
    off = sink.status(ChannelState.OFF)
    assert off.reason == f"no serial remote on {remote_profile.port}"
    assert off.source == remote_reader.name
    box = ButtonBox(remote_dir / "ttyUSB-test0")
    sink.status(ChannelState.ON)
    box.write(b"BTN 2\n")
    assert options(sink.inputs(1)) == [2]


def test_a_port_that_cannot_be_opened_is_reported_as_connecting(remote_dir, remote_reader):
    (remote_dir / "ttyUSB-test0").symlink_to(remote_dir / "missing")
    sink = Collector()
    remote_reader.start(sink)
    connecting = sink.status(ChannelState.CONNECTING)
    assert connecting.reason.startswith("cannot open") and "ttyUSB-test0" in connecting.reason


def test_stop_releases_the_port(remote_dir, remote_reader):
    box = ButtonBox(remote_dir / "ttyUSB-test0")
    sink = Collector()
    remote_reader.start(sink)
    sink.status(ChannelState.ON)
    remote_reader.stop()
    remote_reader.stop()
    assert not remote_reader._thread.is_alive()
    assert open_files().count(box.slave_name) == 1  # only the box's own end is still open
    box.unplug()


def test_two_profiles_matching_one_port_never_both_read_it(remote_dir, remote_profile):
    box = ButtonBox(remote_dir / "ttyUSB-test0")
    readers = [SerialRemote(replace(remote_profile, name=name), backoff=FAST) for name in ("one", "two")]
    sink = Collector()
    try:
        for reader in readers:
            reader.start(sink)
        states = sorted(sink.status_any().state.value for _ in readers)
        assert states == ["connecting", "on"]  # the second finds the port locked
        busy = next(s for s in sink.received if s.state is ChannelState.CONNECTING)
        assert "ttyUSB-test0" in busy.reason and "lock" in busy.reason
        box.write(b"BTN 1\nBTN 2\n")
        assert options(sink.inputs(2)) == [1, 2]  # each press once
        assert sink.pending() == []
    finally:
        for reader in readers:
            reader.stop()
        box.unplug()
