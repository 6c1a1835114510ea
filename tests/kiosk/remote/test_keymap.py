"""Keyboard-emulating remotes: Textual key names in, remote presses out."""

from __future__ import annotations

from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.remote import keyboard_remote
from kiosk.remote.buttons import KIOSK_KEYS


def test_keypad_keys_become_remote_presses():
    remote = keyboard_remote()
    assert remote.translate("f15") == ChannelInput(Channel.REMOTE, option=3, detail="key f15 (keypad-f13)")
    assert remote.translate("f19").command is Command.CALL_DOCTOR
    assert remote.translate("f21").command is Command.VOLUME_DOWN


def test_other_keys_and_the_kiosks_own_keys_are_left_to_the_app():
    remote = keyboard_remote()
    for key in [*KIOSK_KEYS, "pageup", "b", "enter", "f12"]:
        assert remote.translate(key) is None
    assert not {k.lower() for k in remote.keys} & KIOSK_KEYS


def test_a_site_can_turn_on_the_presenter(tmp_path):
    path = tmp_path / "devices.yaml"
    path.write_text("profiles:\n  - name: presenter\n    enabled: true\n")
    remote = keyboard_remote(path)
    assert remote.translate("pageup").option == 1
    assert remote.translate("b").command is Command.PAUSE
    assert remote.translate("f14").option == 2  # the keypad still works beside it
