"""`kiosk devices`: what input hardware this machine has, and what the kiosk would use.

Lists the remote profiles and, for each, the device the kiosk would take; every HID device
(hidapi) and serial port (pyserial, plus anything a profile's glob matches); the audio inputs; and
the cameras (Video4Linux nodes, /dev/video*) with whether the pose model is installed.
Only looks: no port or device is opened, so it is safe to run beside a running kiosk.
"""

from __future__ import annotations

import argparse
import sys

import serial.tools.list_ports

from kiosk.config import ConfigError, load_config
from kiosk.remote.buttons import button_name
from kiosk.remote.hid import HidapiBackend, HidDeviceInfo
from kiosk.remote.profiles import (
    BUILTIN_PROFILES,
    HidProfile,
    KeyboardProfile,
    Profile,
    ProfileError,
    SerialProfile,
    load_profiles,
)
from kiosk.remote.serial import matching_ports


def main(argv: list[str]) -> int:
    """Print the devices report; exit status 2 if the profile file is unusable."""
    parser = argparse.ArgumentParser(
        prog="kiosk devices",
        description="List remotes (HID, serial), audio inputs and cameras, and what the kiosk would use.",
    )
    parser.add_argument(
        "--profiles",
        metavar="PATH",
        help="the site's device profile file, adding to or overriding the built-in ones "
        "(default: remote_profiles from the kiosk's config)",
    )
    args = parser.parse_args(argv)
    try:
        if args.profiles is None:
            args.profiles = load_config().remote_profiles
        profiles = load_profiles(args.profiles)
    except (ConfigError, ProfileError) as error:
        print(f"kiosk devices: {error}", file=sys.stderr)
        return 2

    hid_devices, hid_problem = _hid_devices()
    ports = sorted(
        {p.device for p in serial.tools.list_ports.comports()}
        | {port for p in profiles.serial for port in matching_ports(p.port)}
    )

    sources = f"built-in {BUILTIN_PROFILES.name}" + (f" + {args.profiles}" if args.profiles else "")
    print(f"Remote profiles ({sources}):")
    for profile in profiles.all:
        print(f"  {profile.name}: {_profile_line(profile, hid_devices, hid_problem)}")

    print("\nHID devices:")
    if hid_problem:
        print(f"  cannot list HID devices: {hid_problem}")
    elif not hid_devices:
        print("  none found")
    for info in hid_devices:
        users = [p.name for p in profiles.hid if _is_for(p, info)]
        use = f"remote, profile {users[0]}" if users else "not a remote profile, not used"
        what = " ".join(part for part in (info.manufacturer, info.product) if part) or "unnamed"
        print(f"  {info.usb_id} {what} ({info.path.decode(errors='replace')}) -> {use}")

    print("\nSerial ports:")
    if not ports:
        print("  none found")
    for port in ports:
        users = [p.name for p in profiles.serial if port in matching_ports(p.port)]
        print(f"  {port} -> " + (f"remote, profile {users[0]}" if users else "no profile matches, not used"))

    print("\nAudio inputs:")
    for line in _audio_lines():
        print(f"  {line}")

    print("\nCameras:")
    for line in _camera_lines():
        print(f"  {line}")
    return 0


def _camera_lines() -> list[str]:
    from kiosk.camera import list_cameras, model_problem

    cameras = list_cameras()
    problem = model_problem()
    if not cameras:
        return ["no camera (the kiosk runs without one; the Timed Up and Go needs one)"]
    use = f"not used: {problem}" if problem else "would use, with MediaPipe Pose (full model)"
    return [
        f"{c.device} {c.name} -> " + (use if n == 0 else "not used (the first camera is)")
        for n, c in enumerate(cameras)
    ]


def _hid_devices() -> tuple[list[HidDeviceInfo], str]:
    try:
        return HidapiBackend().enumerate(), ""
    except (ImportError, OSError) as error:
        return [], str(error)


def _is_for(profile: HidProfile, info: HidDeviceInfo) -> bool:
    return (info.vendor_id, info.product_id) == (profile.vendor_id, profile.product_id)


def _profile_line(profile: Profile, hid_devices: list[HidDeviceInfo], hid_problem: str) -> str:
    if isinstance(profile, SerialProfile):
        what = f"serial {profile.port} at {profile.baud} baud"
        ports = matching_ports(profile.port)
        use = f"would use {ports[0]}" if ports else f"no port matches {profile.port}"
    elif isinstance(profile, HidProfile):
        what = f"HID {profile.usb_id}"
        found = [info for info in hid_devices if _is_for(profile, info)]
        if found:
            use = f"would use {found[0].path.decode(errors='replace')}"
        else:
            use = f"cannot list HID devices: {hid_problem}" if hid_problem else "not connected"
    else:
        assert isinstance(profile, KeyboardProfile)
        keys = ", ".join(f"{key}={button_name(button)}" for key, button in profile.keys.items())
        what = f"keyboard keys {keys}"
        use = "read from key presses"
    if not profile.enabled:
        use = "disabled"
    return f"{what} -> {use}"


def _audio_lines() -> list[str]:
    try:
        from kiosk.speech.audio import AudioUnavailable, default_input_device, list_input_devices
    except ImportError:
        return ["audio: listing not available"]
    try:
        devices = list_input_devices()
        chosen = default_input_device() if any(d.usable for d in devices) else None
    except AudioUnavailable as error:
        return [f"cannot list audio inputs: {error}"]
    if not devices:
        return ["none found (voice input will be off)"]
    lines = []
    for device in devices:
        use = "would use" if device == chosen else (device.reason or "not used")
        default = ", default" if device.default else ""
        lines.append(f"#{device.index} {device.name} ({device.sample_rate:g} Hz{default}) -> {use}")
    return lines
