"""What the kiosk tells the ward view (protocol §2) and what a station command does (§3).

Both work on the running kiosk through the same operations its clinician screen uses; the app
calls them on its own thread (a command arrives on the client's thread and is handed over with
``app.call_from_thread``).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Protocol

from kiosk.core.room import STAFF_NOTICE
from kiosk.core.session import Phase, Session
from kiosk.core.visits import CANCELLED, runs_cancelled

if TYPE_CHECKING:  # the client (http.client, threads) is not imported with the live status
    from kiosk.sync.client import Outcome


class Kiosk(Protocol):
    """What a command needs of the kiosk app."""

    session: Session
    store: Any

    def clinician_continue(self) -> None: ...
    def person_lost(self, detail: str = ...) -> None: ...
    def person_back(self, detail: str = ...) -> None: ...
    def end_session(self, reason: str) -> None: ...


def live_status(session: Session) -> dict[str, Any]:
    """The kiosk as the ward view shows it (the client adds ``kiosk_id`` and ``at``)."""
    snap = session.snapshot()
    started = session.phase is not Phase.WELCOME
    return {
        "session_id": session.id if started else None,
        "patient_id": session.patient_id if started else None,
        "phase": snap.phase.value,
        "question": snap.number,
        "of": snap.count,
        "paused": snap.paused,
        "person_away": not snap.person_present,
        "unattended": snap.unattended,
        "doctor_called": snap.halted,
        # voice is not heard well in this room, and patients are steered to touch (kiosk.core.room)
        "voice_room": STAFF_NOTICE if "voice_room" in snap.adaptations else None,
        "simulated": False,
    }


def apply_command(kiosk: Kiosk, command: Mapping[str, Any]) -> Outcome | None:
    """Carry out a station command on the running session: ("done", None) or ("refused", why);
    None when another kiosk process on this data directory runs that session (it answers)."""
    kind, session = command.get("kind"), kiosk.session
    if (
        command.get("session_id") != session.id
        and kiosk.store is not None
        and kiosk.store.held_elsewhere(str(command.get("session_id")))
    ):
        return None
    if session.phase is Phase.WELCOME or command.get("session_id") != session.id:
        return "refused", f"session {command.get('session_id')} is not the one running on this kiosk"
    if session.finished:
        return "refused", f"session {session.id} is finished"
    snap = session.snapshot()
    by = f"ward station, {command.get('by') or 'staff'}"
    if kind == "continue":
        if not (snap.halted or snap.paused or snap.unattended):
            return "refused", "the session is not waiting for a doctor"
        kiosk.clinician_continue()  # unattended: logged; the kiosk still waits for the patient's touch
    elif kind == "person_away":
        if not snap.person_present:
            return "refused", "the patient is already marked away"
        kiosk.person_lost(by)
    elif kind == "person_back":
        if snap.person_present:
            return "refused", "the patient is not marked away"
        kiosk.person_back(by)
    elif kind == "end":
        kiosk.end_session(f"ended from the ward station by {command.get('by') or 'staff'}")
    else:
        return "refused", f"unknown command {kind!r}"
    return "done", None


def end_cancelled(kiosk: Kiosk, order_ids: tuple[str, ...]) -> str | None:
    """The ward cancelled these orders (protocol §4, the orders poll's ``cancelled``): a running
    session of one of them ends as staff's "End session" ends one (stored as abandoned with
    why, every answer given kept; a battery's next instruments never start). Returns the ended
    visit's language (its patient reads a calm end in it), None when nothing here ran one."""
    session = kiosk.session
    if session.phase is Phase.WELCOME or session.finished or not runs_cancelled(session.visit, order_ids):
        return None
    language = session.language
    kiosk.end_session(CANCELLED)
    return language
