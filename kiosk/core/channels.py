"""What input channels hand to the session: answers, commands and channel status.

Every way a patient can act on the kiosk -- voice, touch, the remote control, the keyboard --
ends up as a :class:`ChannelInput`. Channels that run on background threads (audio, serial, HID)
build these values and hand them to a *sink*; they never touch the session or a widget directly.
The Textual app's sink posts them to the UI thread, a replay's sink calls the session.

This module is the contract between the channel packages (``kiosk.speech``, ``kiosk.remote``)
and the session core, so it stays small, pure Python and free of Textual.
"""

from __future__ import annotations

from collections.abc import Callable
from enum import Enum
from typing import Protocol

from basis import record


class Channel(str, Enum):
    """Where an input came from; recorded with every answer and published to the QoS engine."""

    VOICE = "voice"
    TOUCH = "touch"
    REMOTE = "remote"
    KEYBOARD = "keyboard"
    #: sees, gives no answers: pose landmarks and presence (kiosk.camera)
    CAMERA = "camera"


class Command(str, Enum):
    """Things a patient (or the remote's extra buttons) can ask for besides an answer."""

    PAUSE = "pause"
    RESUME = "resume"
    CALL_DOCTOR = "call_doctor"
    REPEAT = "repeat"
    VOLUME_UP = "volume_up"
    VOLUME_DOWN = "volume_down"
    #: "No, that's wrong" / the Change button: take back the last answer while it can still be
    #: changed (the session decides how long that is)
    UNDO = "undo"


@record
class ChannelInput:
    """One thing the patient did: chose an answer option, or gave a command.

    ``option`` is the 1-based position of the answer on the current question -- the number shown
    on its button and printed on the remote's button -- never the points it scores.
    Exactly one of ``option`` and ``command`` is set.
    """

    channel: Channel
    option: int | None = None
    command: Command | None = None
    #: what was actually received, for the session log: an utterance, a key, a device's button name
    detail: str = ""
    #: for voice: the recogniser's confidence in [0, 1]; None for channels without one
    confidence: float | None = None
    #: the channel is not sure enough to store this answer as heard: the session asks the patient
    #: to confirm it ("I heard: Independent. Is that right?") before recording it
    needs_confirmation: bool = False

    def __post_init__(self) -> None:
        if (self.option is None) == (self.command is None):
            raise ValueError("a ChannelInput carries exactly one of option and command")
        if self.option is not None and self.option < 1:
            raise ValueError(f"answer options are numbered from 1, got {self.option}")


class PresenceSource(str, Enum):
    """Who says whether the patient is in front of the kiosk."""

    #: the camera channel (``kiosk.camera``): a person found in its frames, or none
    CAMERA = "camera"
    #: staff: "Patient away" / "Patient back" on the clinician screen or from the ward station
    STAFF = "staff"


@record
class Presence:
    """A presence source's report: whether a person is in front of the kiosk now.

    Handed to the session like a :class:`ChannelInput` (``Session.handle``): a person not seen
    stops the question clock; seen again, the test goes on where it was. A source reports on
    change; the session ignores a report that changes nothing (and logs it).
    """

    seen: bool
    source: PresenceSource
    #: what the source saw or who pressed, for the session log ("ward station", "no person in 15 frames")
    detail: str = ""


class ChannelState(str, Enum):
    """Whether a channel can currently take input, as the UI shows it."""

    ON = "on"
    OFF = "off"  # not available on this machine (no device, no model, no audio)
    CONNECTING = "connecting"  # looking for a device or reconnecting with backoff
    LOST = "lost"  # was working and went away (unplugged, read error)


@record
class ChannelStatus:
    """A change in a channel's availability, e.g. the serial remote was unplugged."""

    channel: Channel
    state: ChannelState
    #: which source this is about: "espeak-ng", "pocketsphinx", "serial /dev/ttyUSB0", ...
    source: str = ""
    #: one sentence a clinician can act on, e.g. "no microphone found"
    reason: str = ""
    #: the same reason as a key of the kiosk's screen texts (``kiosk/core/words``), so a
    #: patient's screen can say it in the patient's language; empty when there is none
    reason_key: str = ""


#: Where a channel delivers what it receives. Called from the channel's own thread.
Sink = Callable[[ChannelInput | ChannelStatus | Presence], None]


class InputSource(Protocol):
    """A running channel (a remote reader, a recogniser...). ``start`` must not block."""

    name: str

    def start(self, sink: Sink) -> None:
        """Begin delivering inputs and status changes to ``sink`` from a background thread."""

    def stop(self) -> None:
        """Stop delivering and release the device; safe to call twice."""
