"""Remotes that emulate a keyboard: the Textual app asks which button a key press means.

Such a remote needs no thread and no device access: its presses arrive as key events in the
app, which calls :meth:`KeyboardRemote.translate` and forwards any result to the session.
Keys are Textual key names (``"f13"``, ``"pageup"``, ``"b"``); profiles may not claim the
kiosk's own keys (see :data:`~kiosk.remote.buttons.KIOSK_KEYS`).
"""

from __future__ import annotations

from collections.abc import Iterable

from kiosk.core.channels import ChannelInput
from kiosk.remote.buttons import Button, to_input
from kiosk.remote.profiles import KeyboardProfile


class KeyboardRemote:
    """Translates key names to remote presses for all enabled keyboard-emulating profiles."""

    def __init__(self, profiles: Iterable[KeyboardProfile]) -> None:
        self._keys: dict[str, tuple[Button, str]] = {}
        for profile in profiles:
            if profile.enabled:
                for key, button in profile.keys.items():
                    self._keys.setdefault(key, (button, profile.name))

    @property
    def keys(self) -> frozenset[str]:
        """Every key name that means a button."""
        return frozenset(self._keys)

    def translate(self, key: str) -> ChannelInput | None:
        """The remote press ``key`` stands for, or None if no profile uses that key."""
        found = self._keys.get(key)
        if found is None:
            return None
        button, profile = found
        return to_input(button, f"key {key} ({profile})")
