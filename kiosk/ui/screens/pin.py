"""The PIN pad in front of the clinician screens: big on-screen keys for touch, digits on a keyboard.

The pad keeps what is typed in its own field: after a wrong PIN the field is emptied and the next
digits go into it at once (typing does not wait for the message), and while the guard makes the
next attempt wait, digits are still taken and only OK says how long is left.
"""

from __future__ import annotations

import math

from textual import events, on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical

from kiosk.core.pin import MAX_DIGITS, PinGuard
from kiosk.ui.screens.base import ClinicianScreen
from kiosk.ui.widgets.keypad import Keypad, keyboard_key, press
from kiosk.ui.widgets.literal import Button, Label, Static


class PinScreen(ClinicianScreen):
    """Asks for the clinician PIN; dismisses with True when it is right, None on Back or Escape."""

    #: the pad's own keys come first: a focused button must not take Enter or the digits
    AUTO_FOCUS = ""

    def __init__(self, guard: PinGuard) -> None:
        """``guard`` checks attempts and counts failures (across restarts)."""
        super().__init__()
        self._guard = guard
        self._typed = ""

    def compose(self) -> ComposeResult:
        """The title, the masked digits, the message line and the way back beside the keypad, which
        takes the height left: the whole pad and "Back to the patient" fit from 64x18 up."""
        with Horizontal(classes="clinician", id="pin-pad"):
            with Vertical(id="pin-side"):
                yield Static("Clinician access", classes="heading")
                yield Label("Enter the PIN on the keys (or the keyboard), then OK.", id="pin-help")
                yield Static("", id="pin")
                yield Label("", id="pin-error")
                yield Button("Back to the patient", id="pin-back")
            yield Keypad(self, id="pin-keys")

    def on_mount(self) -> None:
        """Say at once when the pad is still waiting after earlier failures."""
        self._show()
        if (left := self._guard.wait_left()) > 0:
            self._wait_message(left)

    def _show(self) -> None:
        self.query_one("#pin", Static).update(" ".join("●" * len(self._typed)) or " ")

    def _wait_message(self, seconds: float) -> None:
        minutes = math.ceil(seconds / 60)
        when = f"{math.ceil(seconds)} s" if seconds < 120 else f"{minutes} minutes"
        self.query_one("#pin-error", Label).update(f"Too many wrong PINs: try again in {when}.")

    def type_digit(self, digit: str) -> None:
        """One digit typed on the pad or the keyboard."""
        if len(self._typed) < MAX_DIGITS:
            self._typed += digit
            self._show()

    def delete(self) -> None:
        """Take back the last digit."""
        self._typed = self._typed[:-1]
        self._show()

    def submit(self) -> None:
        """Check what was typed; a wrong PIN empties the field and says so."""
        if not self._typed:
            return
        verdict = self._guard.attempt(self._typed)
        if verdict.ok:
            self.dismiss(True)
            return
        if verdict.early:  # not checked: keep the digits, say how long is left
            self._wait_message(verdict.wait_s)
            return
        self._typed = ""
        self._show()
        if verdict.wait_s > 0:
            self._wait_message(verdict.wait_s)
        else:
            self.query_one("#pin-error", Label).update("Wrong PIN.")

    @on(Button.Pressed, "#pin-back")
    def _back(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss(None)

    def on_key(self, event: events.Key) -> None:
        """Digits, Backspace and Enter from a keyboard; Escape is the base screen's "back"."""
        if (key := keyboard_key(event)) is None:
            return
        press(self, key)
        event.stop()
        event.prevent_default()
