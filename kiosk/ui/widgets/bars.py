"""The bars around every patient screen: progress, channels, adaptation notice and controls."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.containers import Horizontal
from textual.message import Message

from basis import record
from kiosk.core.channels import Command
from kiosk.ui.widgets.literal import Button, Static
from kiosk.ui.widgets.text import ui_text


@record
class ChannelLine:
    """How one channel is shown: its name, a word for its state, and whether it takes input now."""

    name: str
    state: str
    live: bool
    #: why it is off, for the clinician standing by ("no microphone found")
    reason: str = ""


class AdaptationBanner(Static):
    """A notice of how the kiosk changed itself, e.g. "voice answers paused — touch or press".

    Hidden while there is nothing to say.
    """

    def show(self, message: str | None) -> None:
        """Show ``message``, or hide the banner when it is None or empty."""
        self.update(message or "")
        self.display = bool(message)


class VoiceAgainButton(Button):
    """ "Answer by voice again": shown with the voice-off notice, so the patient can undo it (the
    session decides; touch answers alone never give the voice evidence that would lift it)."""

    class Requested(Message):
        """The patient asked to answer by voice again."""

    def __init__(self, language: str) -> None:
        """Label the button in ``language``; hidden until :meth:`show` says otherwise."""
        super().__init__(ui_text(language, "voice_again"), id="voice-again")
        self.display = False

    def show(self, shown: bool) -> None:
        """Show or hide the button."""
        self.display = shown

    def on_button_pressed(self, event: Button.Pressed) -> None:
        """A touch on the button is a request to the session, forwarded by the app."""
        event.stop()
        self.post_message(self.Requested())


class ControlBar(Horizontal):
    """Pause, Repeat and Call-doctor, always visible at the bottom of the patient's screens."""

    class Commanded(Message):
        """The patient touched one of the control buttons."""

        def __init__(self, command: Command) -> None:
            self.command = command
            """What the patient asked for."""
            super().__init__()

    def __init__(self, language: str, *, paused: bool = False, repeat: bool = True) -> None:
        """Label the buttons in ``language``; while ``paused`` the pause button resumes. Repeat is
        shown only while ``repeat`` (the kiosk can speak: without a voice it would do nothing)."""
        super().__init__(id="controls")
        self.language = language
        self.paused = paused
        self.repeat = repeat

    def compose(self) -> ComposeResult:
        """Pause (or Continue), Repeat and Call doctor, each with its key letter."""
        if self.paused:
            yield Button(ui_text(self.language, "resume"), id="resume", classes="control")
        else:
            yield Button(ui_text(self.language, "pause"), id="pause", classes="control")
            yield Button(ui_text(self.language, "repeat"), id="repeat", classes="control")
        yield Button(ui_text(self.language, "call_doctor"), id="call-doctor", classes="control")

    def on_mount(self) -> None:
        """Hide Repeat if the kiosk cannot speak."""
        self.show_repeat(self.repeat)

    def show_repeat(self, shown: bool) -> None:
        """Offer Repeat or not (voice out came or went)."""
        self.repeat = shown
        for button in self.query("#repeat").results(Button):
            button.display = shown

    def on_button_pressed(self, event: Button.Pressed) -> None:
        """Turn a touched control into the command it stands for."""
        event.stop()
        command = {
            "pause": Command.PAUSE,
            "resume": Command.RESUME,
            "repeat": Command.REPEAT,
            "call-doctor": Command.CALL_DOCTOR,
        }[event.button.id or ""]
        self.post_message(self.Commanded(command))
