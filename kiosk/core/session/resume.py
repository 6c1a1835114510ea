"""Continuing a stored, unfinished session (``kiosk.store.records.StoredSession``) after a crash:
the QoS engine brought back to where it was, session time continued after the last record, and
the adaptations the patient and the clinician had left in force.

Used by :meth:`kiosk.core.session.Session.from_stored`; apart so the session's constructor stays
about a session, not about a store's records."""

from __future__ import annotations

from typing import Any

from kiosk.core.answerers import answerer_of
from kiosk.core.session.ports import QosEngine


def replay_into(engine: QosEngine | None, stored: Any) -> dict[str, Any]:
    """Replay ``stored``'s context trace into ``engine`` and return the session's constructor
    keywords that continue it (its identity, answers so far, and the session time to go on from)."""
    for event in stored.trace:
        if engine is not None:
            engine.update(event["t"], set=event.get("set") or {}, emit=list(event.get("emit") or []))
    last = max((e["t"] for e in stored.trace), default=0.0)
    # the model's timers that fired after the last context (stored as metrics) are not run twice
    last_timed = max((m.t for m in stored.metrics), default=last)
    if engine is not None and last_timed > last:
        engine.advance(last_timed)
    return {
        "patient_id": stored.patient_id,
        "language": stored.language,
        "answered_by": stored.answered_by,
        "answerer": answerer_of(stored.log),  # for the visit's later instruments
        "session_id": stored.id,
        # the crash took some time: resumed batches come a second after the stored ones
        "t_offset": max(last, last_timed) + 1.0,
        "resume_answers": {a.item_id: a for a in stored.answers},
        "resume_not_answered": tuple(stored.not_answered),
        "familiarisation": False,
    }


def restore_adaptation(adaptation: Any, stored: Any) -> None:
    """Put back the adaptations in force when ``stored`` stopped, and the clinician's switch: a
    crash must not undo the clinician's switch or listen again to a patient it stopped hearing."""
    if adaptation is None:
        return
    active: dict[str, bool] = {}
    for record in stored.adaptations:
        active[record.name] = record.active
    switches = [entry.detail for entry in stored.log if entry.kind == "adaptation_enabled"]
    enabled = switches[-1] == "on" if switches else adaptation.enabled
    adaptation.restore((name for name, on in active.items() if on), enabled)
