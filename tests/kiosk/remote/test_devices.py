"""`kiosk devices` on this machine: real hidapi, real serial port listing, real audio listing."""

from __future__ import annotations

import hid
import pytest

from kiosk.cli import main

from .boxes import ButtonBox


@pytest.fixture(autouse=True)
def devices_config_home(tmp_path, monkeypatch):
    """No kiosk config unless a test writes one: keep the developer's own config out."""
    monkeypatch.delenv("KIOSK_CONFIG", raising=False)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config-home"))


def section(out: str, title: str) -> list[str]:
    """The indented lines under a heading of the report."""
    lines = out.splitlines()
    start = lines.index(title) + 1
    body = []
    for line in lines[start:]:
        if not line.startswith("  "):
            break
        body.append(line.strip())
    return body


def test_devices_lists_every_kind_and_what_the_kiosk_would_use(capsys):
    assert main(["devices"]) == 0
    out = capsys.readouterr().out
    profiles = section(out, "Remote profiles (built-in devices.yaml):")
    assert "serial-usb: serial /dev/ttyUSB* at 9600 baud -> " in "\n".join(profiles)
    assert any(line.startswith("keypad-f13: keyboard keys f13=1,") for line in profiles)
    assert "presenter: keyboard keys pageup=1, pagedown=2, f5=repeat, b=pause -> disabled" in profiles

    present = hid.enumerate()  # what the real hidapi sees here (nothing on the build machines)
    hid_lines = section(out, "HID devices:")
    if present:
        assert len(hid_lines) == len(present)
    else:
        assert hid_lines == ["none found"]
        assert "hid-bigbutton: HID 1209:0001 -> not connected" in profiles
    assert section(out, "Serial ports:")
    assert section(out, "Audio inputs:")  # a device list, or the reason there is none


def test_devices_shows_which_port_a_site_profile_would_take(tmp_path, capsys):
    box = ButtonBox(tmp_path / "ttyUSB-test0")
    site = tmp_path / "site.yaml"
    port = box.slave_name  # a profile's port is under /dev: the box's own pty
    site.write_text(f"profiles:\n  - name: serial-usb\n    port: {port}\n")
    try:
        assert main(["devices", "--profiles", str(site)]) == 0
    finally:
        box.unplug()
    out = capsys.readouterr().out
    assert f"Remote profiles (built-in devices.yaml + {site}):" in out
    assert f"serial-usb: serial {port} at 9600 baud -> would use {port}" in out
    assert f"{port} -> remote, profile serial-usb" in section(out, "Serial ports:")


def test_the_site_file_named_in_the_config_is_used(tmp_path, capsys, monkeypatch):
    site = tmp_path / "site.yaml"
    site.write_text("profiles:\n  - name: presenter\n    enabled: true\n")
    config = tmp_path / "config.yaml"
    config.write_text(f"remote_profiles: {site}\n")
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    assert main(["devices"]) == 0
    out = capsys.readouterr().out
    assert f"Remote profiles (built-in devices.yaml + {site}):" in out
    assert "presenter: keyboard keys pageup=1, pagedown=2, f5=repeat, b=pause -> read from key presses" in out


def test_a_bad_profile_file_is_one_line_and_exit_status_2(tmp_path, capsys):
    site = tmp_path / "site.yaml"
    site.write_text("profiles:\n  - name: serial-usb\n    baud: -3\n")
    assert main(["devices", "--profiles", str(site)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        f"kiosk devices: {site}:3:5: profile 'serial-usb', field 'baud': must be at least 1, got -3\n"
    )
