"""What the channel bar shows: the latest status of every channel source, and its activity.

Channels report :class:`~kiosk.core.channels.ChannelStatus` from their own threads (the app hands them
over on the UI thread). Several sources can stand for one channel (a serial and a HID remote):
the channel is live when any of them is.
"""

from __future__ import annotations

from kiosk.core.channels import Channel, ChannelState, ChannelStatus
from kiosk.ui.widgets.bars import ChannelLine
from kiosk.ui.widgets.text import ui_text

#: the indicators in display order: voice out, voice in, remote, touch
VOICE_OUT, VOICE_IN, REMOTE, TOUCH = "voice_out", "voice_in", "remote", "touch"
_ORDER = (VOICE_OUT, VOICE_IN, REMOTE, TOUCH)
#: the camera: on the clinician screen only (it takes no answers, so the patient's bar leaves it out)
CAMERA = "camera"
#: when no source of a channel is on, the most hopeful state wins
_PRIORITY = (ChannelState.CONNECTING, ChannelState.LOST, ChannelState.OFF)


class ChannelBoard:
    """Latest status per indicator and source, plus whether the kiosk is speaking or listening."""

    def __init__(self, voice_out_source: str) -> None:
        """``voice_out_source`` is the source name voice-out statuses carry (e.g. "espeak-ng");
        every other voice status is about voice in."""
        self._voice_out_source = voice_out_source
        self._statuses: dict[str, dict[str, ChannelStatus]] = {name: {} for name in (*_ORDER, CAMERA)}
        self._statuses[TOUCH]["screen"] = ChannelStatus(Channel.TOUCH, ChannelState.ON, "screen")
        self.speaking = False
        self.listening = False

    def indicator(self, status: ChannelStatus) -> str:
        """Which indicator a status belongs to."""
        if status.channel is Channel.VOICE:
            return VOICE_OUT if status.source == self._voice_out_source else VOICE_IN
        return {Channel.REMOTE: REMOTE, Channel.TOUCH: TOUCH, Channel.CAMERA: CAMERA}.get(status.channel, TOUCH)

    def update(self, status: ChannelStatus) -> None:
        """Remember the latest status of its source."""
        self._statuses[self.indicator(status)][status.source] = status

    def patient_reason(self, name: str, language: str) -> str:
        """Why the indicator is off, in ``language`` when its source gave a screen-text key
        (no speech model for Spanish), else as the source said it."""
        state, reason = self.state(name)
        status = next((s for s in self._statuses[name].values() if s.reason == reason and s.reason_key), None)
        return ui_text(language, status.reason_key, default=reason) if reason and status else reason

    def state(self, name: str) -> tuple[ChannelState, str]:
        """The indicator's state and, when it is not on, the reason of its most hopeful source."""
        statuses = list(self._statuses[name].values())
        if any(s.state is ChannelState.ON for s in statuses):
            return ChannelState.ON, ""
        for state in _PRIORITY:
            for status in statuses:
                if status.state is state:
                    return state, status.reason
        return ChannelState.OFF, ""

    def lines(self, language: str, patient: bool = True) -> tuple[ChannelLine, ...]:
        """The indicators as the bar shows them, in ``language``; for a ``patient`` the reasons
        that have screen words are said in the language, for the clinician as the source said."""
        lines = []
        for name in _ORDER:
            state, _ = self.state(name)
            reason = self.patient_reason(name, language) if patient else self.state(name)[1]
            # the state word agrees with the channel's gender where the language needs it
            word = ui_text(language, f"{state.value}_{name}")
            if state is ChannelState.ON and name == VOICE_OUT and self.speaking:
                word = ui_text(language, "speaking")
            elif state is ChannelState.ON and name == VOICE_IN and self.listening:
                word = ui_text(language, "listening")
            lines.append(ChannelLine(ui_text(language, f"channel_{name}"), word, state is ChannelState.ON, reason))
        return tuple(lines)
