"""Live adaptation inside a session: the policy (:class:`kiosk.core.adaptation.Adaptation`) decides from
the QoS metrics; the session records each change and acts on it (stops or resumes listening,
speaks more slowly, gives a slow patient longer attempts from the next one opened)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kiosk.core.session.events import AdaptationChanged
from kiosk.core.session.publishing import Operation

if TYPE_CHECKING:
    from kiosk.core.session.core import Session


class LiveAdaptation:
    """Adaptation switches and their effects (a mixin of :class:`~kiosk.core.session.Session`)."""

    def request_voice(self: Session) -> None:
        """The patient asks to answer by voice again (lifts a voice-off adaptation; logged)."""
        with Operation(self) as t:
            if self.adaptation is None:
                return
            changes = self.adaptation.patient_requests_voice()
            if changes:
                self._log(t, "voice_requested", "the patient asked to answer by voice again")
            for change in changes:
                self._apply_adaptation(t, change)

    def set_voice_available(self: Session, available: bool) -> None:
        """Whether voice in works on this kiosk (the UI knows it from the voice-in channel's status).

        Assumed True until told otherwise, so sessions without a UI (replays, tests) behave as
        the policy says. While False, the voice_off adaptation is neither switched on nor
        announced -- "I am having trouble hearing you" is untrue when voice in is not running --
        and one in force is lifted (recorded with that reason) without a voice_on message. The
        QoS contexts and the listening state are not affected.
        """
        with Operation(self) as t:
            if available == self._voice_available:
                return
            self._voice_available = available
            self._log(t, "voice_in", "available" if available else "unavailable")
            if self.adaptation is not None:
                for change in self.adaptation.hold("voice_off", not available, "voice in is unavailable"):
                    self._apply_adaptation(t, change)

    def set_adaptation_enabled(self: Session, enabled: bool) -> None:
        """The clinician turns live adaptation on or off (off lifts every active adaptation)."""
        with Operation(self) as t:
            if self.adaptation is not None:
                self._log(t, "adaptation_enabled", "on" if enabled else "off")
                for change in self.adaptation.set_enabled(enabled):
                    self._apply_adaptation(t, change)

    def _active_adaptations(self: Session) -> frozenset[str]:
        return frozenset(self.adaptation.active) if self.adaptation is not None else frozenset()

    def _speech_rate(self: Session) -> float:
        return self.adaptation.speech_rate if self.adaptation is not None else 1.0

    def _attempt_window(self: Session) -> float:
        """How long an attempt opened now waits: longer while ``longer_attempts`` is on."""
        factor = self.adaptation.attempt_factor if self.adaptation is not None else 1.0
        return self.timing.attempt_window_s * factor

    def _apply_adaptation(self: Session, t: float, change: Any) -> None:
        """Publish and store one adaptation change and act on it (voice on/off, slower speech)."""
        if self.store is not None:
            self.store.record_adaptation(self.id, t=t, name=change.name, active=change.active, reason=change.reason)
        self._emit(AdaptationChanged(t, change.name, change.active, change.reason))
        if change.name == "voice_off":
            if self._voice_available:  # hearing the patient again means nothing without voice in
                self._message(t, "voice_off" if change.active else "voice_on")
            self._update_listening(t)
        elif change.name == "slow_speech" and change.active and self.current_attempt is not None:
            self._prompt_question(t, repeat=True)
        elif change.name == "longer_attempts" and change.active and self.current_attempt is not None:
            # the attempt open now gets the extra time too (it opened with the normal window)
            extra = self._attempt_window() - self.timing.attempt_window_s
            if (remaining := self._timers.attempt_remaining()) is not None:
                self._timers.at_least(remaining + extra)
