"""Cameras as `kiosk devices` and the kiosk's start see them: Video4Linux nodes with their driver's
names, and "no camera" on a machine without one (this one), where the kiosk runs as before."""

from __future__ import annotations

import glob

from kiosk.camera import camera_status, list_cameras
from kiosk.cli import main
from kiosk.core.channels import Channel, ChannelState
from tests.kiosk.remote.test_devices import devices_config_home, section  # noqa: F401 (a fixture)


def test_the_video_nodes_are_listed_with_their_names(tmp_path):
    for number, name in ((10, "Logitech C920"), (2, "Integrated Camera")):
        (tmp_path / f"video{number}").touch()
        (tmp_path / "names" / f"video{number}").mkdir(parents=True)
        (tmp_path / "names" / f"video{number}" / "name").write_text(name + "\n")
    (tmp_path / "video3").touch()  # a node whose name cannot be read
    found = list_cameras(str(tmp_path / "video*"), str(tmp_path / "names"))
    assert [(c.device.rsplit("/", 1)[1], c.name) for c in found] == [
        ("video2", "Integrated Camera"),
        ("video3", "unnamed"),
        ("video10", "Logitech C920"),
    ]


def test_devices_says_what_this_machine_has(capsys):
    assert main(["devices"]) == 0
    lines = section(capsys.readouterr().out, "Cameras:")
    if glob.glob("/dev/video*"):
        assert all("/dev/video" in line for line in lines)
    else:
        assert lines == ["no camera (the kiosk runs without one; the Timed Up and Go needs one)"]


def test_without_a_camera_the_channel_is_off_with_the_reason():
    status = camera_status()
    assert status.channel is Channel.CAMERA
    if not glob.glob("/dev/video*"):
        assert (status.state, status.reason) == (ChannelState.OFF, "no camera found; the kiosk runs without one")
