"""kiosk.remote.open_sources: what the app starts, one source per enabled serial and HID profile."""

from __future__ import annotations

import pytest

from kiosk.core.channels import ChannelInput, ChannelState, ChannelStatus
from kiosk.remote import ProfileError, open_sources
from kiosk.remote.reconnect import Backoff

from .boxes import ButtonBox, Collector


def test_each_source_reports_its_own_state_and_the_connected_one_delivers(tmp_path):
    site = tmp_path / "site.yaml"
    box = ButtonBox(tmp_path / "ttyUSB-test0")
    # keep the test off any real /dev/ttyUSB*/ttyACM* the machine may have: the box's own pty, and
    # a pattern under /dev that matches nothing
    site.write_text(
        f"profiles:\n  - name: serial-usb\n    port: {box.slave_name}\n"
        f"  - name: serial-acm\n    port: /dev/ttyACM-kiosk-test*\n"
    )
    sources = open_sources(site, backoff=Backoff(0.01, 2, 0.05))
    assert [s.name for s in sources] == [f"serial {box.slave_name}", "serial /dev/ttyACM-kiosk-test*", "hid 1209:0001"]
    sink = Collector()
    for source in sources:
        source.start(sink)
    try:
        statuses = {}
        while len(statuses) < 3:
            item = sink.next()
            assert isinstance(item, ChannelStatus)
            statuses[item.source] = item.state
        assert statuses == {
            sources[0].name: ChannelState.ON,
            sources[1].name: ChannelState.OFF,
            sources[2].name: ChannelState.OFF,
        }  # real hidapi: no HID remote here
        box.write(b"BTN 1\n")
        press = sink.next()
        assert isinstance(press, ChannelInput) and press.option == 1
    finally:
        for source in sources:
            source.stop()
        box.unplug()


def test_a_bad_site_file_opens_nothing(tmp_path):
    site = tmp_path / "site.yaml"
    site.write_text("profiles:\n  - name: serial-usb\n    lines: {}\n")
    with pytest.raises(ProfileError, match="profile 'serial-usb', field 'lines': must be a non-empty mapping"):
        open_sources(site)
