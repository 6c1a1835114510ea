"""Device profiles: the built-in file, a site's overrides, and one clear message for each mistake."""

from __future__ import annotations

import pytest

from kiosk.core.channels import Command
from kiosk.remote.profiles import BUILTIN_PROFILES, ProfileError, load_profiles


def write(tmp_path, text: str):
    path = tmp_path / "my-devices.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_builtin_profiles_cover_every_kind_and_every_button():
    profiles = load_profiles()
    assert {p.name for p in profiles.serial} == {"serial-usb", "serial-acm"}
    assert [p.name for p in profiles.hid] == ["hid-bigbutton"]
    assert [p.name for p in profiles.keyboard] == ["keypad-f13"]  # the presenter is off by default
    wanted = {1, 2, 3, 4, Command.REPEAT, Command.PAUSE, Command.CALL_DOCTOR, Command.VOLUME_UP, Command.VOLUME_DOWN}
    assert set(profiles.serial[0].lines.values()) == wanted
    assert set(profiles.hid[0].buttons) == wanted
    assert set(profiles.keyboard[0].keys.values()) == wanted


def test_a_site_file_overrides_fields_disables_and_adds_profiles(tmp_path):
    path = write(
        tmp_path,
        """
profiles:
  - name: serial-usb
    port: /dev/serial/by-id/usb-Clarc*
    baud: 19200
  - name: hid-bigbutton
    enabled: false
  - name: ward-3-box
    kind: serial
    port: /dev/ttyS4
    lines: {"K1": 1, "K2": 2, "HELP": call_doctor}
""",
    )
    profiles = load_profiles(path)
    usb = next(p for p in profiles.serial if p.name == "serial-usb")
    assert (usb.port, usb.baud, usb.lines["BTN 3"]) == ("/dev/serial/by-id/usb-Clarc*", 19200, 3)
    assert profiles.hid == []
    ward = next(p for p in profiles.serial if p.name == "ward-3-box")
    assert ward.lines == {"K1": 1, "K2": 2, "HELP": Command.CALL_DOCTOR} and ward.baud == 9600


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "profiles:\n  - name: serial-usb\n    baud: fast\n",
            "profile 'serial-usb', field 'baud': must be a whole number, got 'fast'",
        ),
        (
            "profiles:\n  - name: new\n    kind: serial\n    port: /dev/x\n    lines: {BTN 1: 5}\n",
            "profile 'new', field 'lines.BTN 1': answer buttons are 1 to 4, got 5",
        ),
        (
            "profiles:\n  - name: new\n    kind: serial\n    lines: {BTN 1: 1}\n",
            "profile 'new', field 'port': is required",
        ),
        (
            "profiles:\n  - name: serial-usb\n    baudrate: 9600\n",
            "profile 'serial-usb', field 'baudrate': is not a field of a serial profile",
        ),
        (
            "profiles:\n  - name: new\n    kind: usb\n",
            "profile 'new', field 'kind': must be one of serial, hid, keyboard, got 'usb'",
        ),
        (
            "profiles:\n  - name: hid-bigbutton\n    vendor_id: 0x12345\n",
            "profile 'hid-bigbutton', field 'vendor_id': must be from 0 to 65535, got 74565",
        ),
        (
            "profiles:\n  - name: hid-bigbutton\n    buttons: {1: {byte: 1}}\n",
            "profile 'hid-bigbutton', field 'buttons.1': must be {byte: N, mask: M} or {byte: N, value: V}",
        ),
        (
            "profiles:\n  - name: hid-bigbutton\n    buttons: {ring: {byte: 1, mask: 1}}\n",
            "profile 'hid-bigbutton', field 'buttons.ring': 'ring' is not a button",
        ),
        (
            "profiles:\n  - name: keypad-f13\n    keys: {p: pause}\n",
            "profile 'keypad-f13', field 'keys.p': key 'p' is one of the kiosk's own keys",
        ),
        (
            "profiles:\n  - name: presenter\n    enabled: true\n    keys: {f13: 4}\n",
            "profile 'presenter', field 'keys.f13': means '4' here but '1' in enabled profile 'keypad-f13'",
        ),
        (
            "profiles:\n  - name: serial-usb\n    enabled: maybe\n",
            "profile 'serial-usb', field 'enabled': must be true or false, got 'maybe'",
        ),
        ("profiles:\n  - kind: serial\n", "profile #1, field 'name': must be a non-empty text"),
        (
            "profiles:\n  - name: a\n    kind: keyboard\n    keys: {f1: 1}\n  - name: a\n",
            "profile 'a', field 'name': appears twice in this file",
        ),
        ("profiles: [\n", ":2:1: YAML syntax: expected the node content"),
        ("profiles:\n  - name: serial-usb\n    baud: 1\n    baud: 2\n", ":4:5: duplicate key 'baud'"),
        ("- just a list\n", "expected a mapping with one key, 'profiles'"),
        # a port is globbed on every connection attempt: /**/* walked the whole file system
        (
            "profiles:\n  - name: serial-usb\n    port: /**/*\n",
            ":3:5: profile 'serial-usb', field 'port': must be a device path under /dev",
        ),
        (
            "profiles:\n  - name: serial-usb\n    port: /dev/**\n",
            ":3:5: profile 'serial-usb', field 'port': may not hold '..' or '**'",
        ),
        ("profiles:\n  - name: serial-usb\n    port: /dev/../etc/*\n", "field 'port': may not hold '..' or '**'"),
        ("profiles:\n  - name: serial-usb\n    port: ttyUSB0\n", "field 'port': must be a device path under /dev"),
        ("profiles:\n  - name: serial-usb\n    port: /dev/*/*/*/*/*\n", "field 'port': must be at most 4 names"),
        (
            'profiles:\n  - name: serial-usb\n    port: "/dev/tty\\nUSB0"\n',
            "field 'port': may not hold spaces or control characters",
        ),
    ],
)
def test_a_mistake_is_one_message_naming_file_profile_and_field(tmp_path, text, message):
    path = write(tmp_path, text)
    with pytest.raises(ProfileError) as caught:
        load_profiles(path)
    assert str(caught.value).startswith(f"{path}:")
    assert message in str(caught.value)
    assert "\n" not in str(caught.value)


def test_an_error_in_a_builtin_field_names_the_builtin_file(tmp_path):
    # the override changes the kind; the built-in's serial fields are now the wrong ones
    path = write(tmp_path, "profiles:\n  - name: serial-usb\n    kind: keyboard\n    keys: {f1: 1}\n")
    with pytest.raises(
        ProfileError,
        match=f"^{BUILTIN_PROFILES}:[0-9]+:5: profile 'serial-usb', field 'baud': is not a field of a keyboard profile",
    ):
        load_profiles(path)


def test_the_message_points_at_the_line_and_column_of_the_field(tmp_path):
    path = write(
        tmp_path,
        """profiles:
  - name: serial-usb
    port: /dev/ttyUSB*
  - name: hid-bigbutton
    buttons:
      1: {byte: 1, mask: 1}
      2: {byte: 99, mask: 2}
""",
    )
    with pytest.raises(ProfileError) as caught:
        load_profiles(path)
    assert str(caught.value) == (
        f"{path}:7:11: profile 'hid-bigbutton', field 'buttons.2.byte': must be from 0 to 63, got 99"
    )


def test_a_missing_site_file_is_named(tmp_path):
    with pytest.raises(ProfileError, match="nowhere.yaml:1:1: cannot read the file: No such file or directory"):
        load_profiles(tmp_path / "nowhere.yaml")


def test_an_empty_site_file_is_named_and_an_empty_list_changes_nothing(tmp_path):
    with pytest.raises(ProfileError, match="my-devices.yaml:1:1: the file is empty"):
        load_profiles(write(tmp_path, "# nothing yet\n"))
    assert load_profiles(write(tmp_path, "profiles: []\n")) == load_profiles()
