"""Big-button remote controls: serial and HID readers that reconnect by themselves, and the
key map of remotes that emulate a keyboard.

The app calls :func:`open_sources` once and starts every source with its sink, and asks
:func:`keyboard_remote` what its key events mean. Device profiles: :mod:`kiosk.remote.profiles`.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from kiosk.core.channels import InputSource
from kiosk.remote.keymap import KeyboardRemote
from kiosk.remote.profiles import ProfileError, load_profiles

if TYPE_CHECKING:
    from kiosk.remote.hid import HidBackend
    from kiosk.remote.reconnect import Backoff

__all__ = ["KeyboardRemote", "ProfileError", "keyboard_remote", "open_sources"]


def open_sources(
    profiles_path: str | Path | None = None, *, backoff: Backoff | None = None, hid_backend: HidBackend | None = None
) -> list[InputSource]:
    """One not-yet-started source per enabled serial and HID profile.

    ``profiles_path`` is the site's profile file from the config (None: built-in profiles only).
    Each source looks for its device until stopped, reporting what it finds as
    :class:`~kiosk.core.channels.ChannelStatus`. Raises :class:`ProfileError` for a bad profile file.
    """
    # the readers load here, not with the package: the UI imports the buttons before the welcome
    from kiosk.remote.hid import HidRemote
    from kiosk.remote.serial import SerialRemote

    profiles = load_profiles(profiles_path)
    sources: list[InputSource] = [SerialRemote(p, backoff=backoff) for p in profiles.serial]
    sources += [HidRemote(p, backend=hid_backend, backoff=backoff) for p in profiles.hid]
    return sources


def keyboard_remote(profiles_path: str | Path | None = None) -> KeyboardRemote:
    """The key map of all enabled keyboard-emulating profiles. Raises :class:`ProfileError`."""
    return KeyboardRemote(load_profiles(profiles_path).keyboard)
