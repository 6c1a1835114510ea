"""Live adaptation inside a session: the policy (:class:`kiosk.core.adaptation.Adaptation`) decides from
the QoS metrics; the session records each change and acts on it (stops or resumes listening,
speaks more slowly, gives a slow patient longer attempts from the next one opened)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from kiosk.core.adaptation import VOICE_OFF
from kiosk.core.room import METRIC, RoomHearing
from kiosk.core.session.events import AdaptationChanged
from kiosk.core.session.ports import SessionStore
from kiosk.core.session.prompts import Prompts
from kiosk.core.session.publishing import Outputs
from kiosk.core.session.state import SessionState
from kiosk.core.session.timers import AttemptClock


class LiveAdaptation:
    """Adaptation switches and their effects; the policy is ``state.adaptation`` (None: none)."""

    def __init__(
        self,
        state: SessionState,
        timers: AttemptClock,
        out: Outputs,
        prompts: Prompts,
        *,
        store: SessionStore | None,
        room: RoomHearing | None = None,
    ) -> None:
        self.state = state
        #: how well voice is heard in this kiosk's room (shared with its other sessions), or None
        self.room = room
        self.timers = timers
        self.out = out
        self.prompts = prompts
        self.store = store

    def observe(self, t: float, metrics: Mapping[str, float], answered: bool) -> None:
        """New QoS metrics at session time ``t`` (``answered``: they followed an answer)."""
        if self.state.adaptation is not None:
            for change in self.state.adaptation.observe(metrics, answered=answered):
                self.apply(t, change)

    def hearing(self, t: float, worked: bool) -> None:
        """One voice hearing's outcome (see :mod:`kiosk.core.room`): the room's measure moves, and
        the policy reads it (voice_room)."""
        if self.room is None:
            return
        value = self.room.add(worked)
        if self.state.adaptation is not None:
            for change in self.state.adaptation.observe({METRIC: value}, answered=False):
                self.apply(t, change)

    def request_voice(self, t: float) -> None:
        """The patient asks to answer by voice again (lifts a voice-off adaptation; logged)."""
        if self.state.adaptation is None:
            return
        changes = self.state.adaptation.patient_requests_voice()
        if changes:
            self.out.log(t, "voice_requested", "the patient asked to answer by voice again")
        for change in changes:
            self.apply(t, change)

    def set_voice_available(self, t: float, available: bool) -> None:
        """Voice in works or not (see ``Session.set_voice_available``)."""
        state = self.state
        if available == state.voice_available:
            return
        state.voice_available = available
        self.out.log(t, "voice_in", "available" if available else "unavailable")
        if state.adaptation is not None:
            for name in sorted(VOICE_OFF):
                for change in state.adaptation.hold(name, not available, "voice in is unavailable"):
                    self.apply(t, change)

    def set_enabled(self, t: float, enabled: bool) -> None:
        """The clinician turns live adaptation on or off (off lifts every active adaptation)."""
        if self.state.adaptation is not None:
            self.out.log(t, "adaptation_enabled", "on" if enabled else "off")
            for change in self.state.adaptation.set_enabled(enabled):
                self.apply(t, change)

    def apply(self, t: float, change: Any) -> None:
        """Publish and store one adaptation change and act on it (voice on/off, slower speech)."""
        state = self.state
        if self.store is not None:
            self.store.record_adaptation(state.id, t=t, name=change.name, active=change.active, reason=change.reason)
        self.out.emit(AdaptationChanged(t, change.name, change.active, change.reason))
        if change.name in VOICE_OFF:
            # said when voice answers stop or come back, not when the other reason changes
            others = VOICE_OFF & state.active_adaptations() - {change.name}
            if state.voice_available and not others:  # hearing the patient again means nothing without voice in
                self.prompts.message(t, "voice_off" if change.active else "voice_on")
            self.prompts.update_listening(t)
        elif change.name == "slow_speech" and change.active and state.current_attempt is not None:
            self.prompts.ask(t, repeat=True)
        elif change.name == "longer_attempts" and change.active and state.current_attempt is not None:
            # the attempt open now gets the extra time too (it opened with the normal window)
            extra = state.attempt_window() - state.timing.attempt_window_s
            if (remaining := self.timers.attempt_remaining()) is not None:
                self.timers.at_least(remaining + extra)
