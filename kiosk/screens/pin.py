"""The PIN prompt in front of the clinician screens."""

from __future__ import annotations

import hmac

from textual import on
from textual.app import ComposeResult
from textual.containers import Vertical
from textual.widgets import Input, Label, Static

from kiosk.screens.base import ClinicianScreen


class PinScreen(ClinicianScreen):
    """Asks for the clinician PIN; dismisses with True when it is right, None on Escape."""

    def __init__(self, pin: str) -> None:
        """``pin`` is the configured clinician PIN."""
        super().__init__()
        self._pin = pin

    def compose(self) -> ComposeResult:
        """A title, a masked input that never blinks, and room for "wrong PIN"."""
        with Vertical(classes="clinician"):
            yield Static("Clinician access", classes="heading")
            yield Label("Enter the PIN and press Enter (Escape goes back to the patient).")
            yield Input(password=True, id="pin", restrict=r"[0-9]*", max_length=12)
            yield Label("", id="pin-error")

    def on_mount(self) -> None:
        """Type straight into the PIN field; no blinking cursor (calm, and stable snapshots)."""
        field = self.query_one("#pin", Input)
        field.cursor_blink = False
        field.focus()

    @on(Input.Submitted, "#pin")
    def _check(self, event: Input.Submitted) -> None:
        event.stop()
        if hmac.compare_digest(event.value.encode(), self._pin.encode()):
            self.dismiss(True)
        else:
            event.input.value = ""
            self.query_one("#pin-error", Label).update("Wrong PIN.")
