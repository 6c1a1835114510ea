"""The frozen picture a screen renders, taken from a session's state and its clock."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from kiosk.core.session.snapshot import Snapshot
from kiosk.core.session.state import SessionState
from kiosk.core.session.timers import AttemptClock


def picture(
    state: SessionState,
    timers: AttemptClock,
    *,
    progress: Mapping[str, Any],
    can_undo: bool,
    part: tuple[int, int] | None = None,
) -> Snapshot:
    """The :class:`Snapshot` of a session's ``state`` and ``timers`` (``Session.snapshot``):
    ``progress`` is the practice's, ``can_undo`` whether the last answer could be taken back now
    (it is offered only while no clock is frozen and no call is being asked back)."""
    open_ = state.open
    practice = state.questionnaire.familiarisation[open_.index] if open_ and open_.practice else None
    item = state.current_item
    items = state.patient_items()
    attempt = state.current_attempt
    return Snapshot(
        phase=state.phase,
        language=state.language,
        item=item,
        number=items.index(item) + 1 if item else None,
        count=len(items),
        practice=practice,
        attempt=attempt,
        remaining=timers.attempt_remaining() if attempt is not None else None,
        paused=timers.paused,
        halted=timers.halted,
        person_present=state.person_present,
        listening=state.listening,
        adaptations=state.active_adaptations(),
        speech_rate=state.speech_rate(),
        answers=dict(state.answers),
        not_answered=tuple(state.not_answered),
        score=state.score,
        prompt=state.prompt,
        interlude=state.interlude(timers.kind),
        **progress,
        confirming=open_.unconfirmed.option if open_ and open_.unconfirmed else None,
        can_undo=can_undo and not timers.frozen and state.call is None,
        unattended=state.unattended,
        calling=state.call.text if state.call is not None else None,
        practice_chosen=open_.chosen if open_ and open_.practice else None,
        part=part,
    )
