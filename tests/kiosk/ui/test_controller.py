"""The kiosk's controller without Textual: session swaps, the clinician's hold, continuing and
ending tests, this kiosk's lease on its session and station commands, on the real session core,
QoS engine and SQLite store with a simulated clock. The UI side is :class:`Drawn`, which records
what the controller asked it to draw and say (the app's half is covered by the Pilot tests)."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from kiosk.config import Config
from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.clock import SimClock
from kiosk.core.session import Phase, Prompt, SessionEvent
from kiosk.core.visits import VisitDesk
from kiosk.store.database import Store
from kiosk.store.lease import Owner
from kiosk.ui.compose import KioskParts, SessionMaker
from kiosk.ui.controller import IN_PROGRESS, KioskController

ATTEMPT_S = 30.0


class Drawn:
    """The UI as the controller sees it: what it was asked to draw, say and do."""

    def __init__(self) -> None:
        self.redraws: list[bool] = []  # one entry per redraw: was it a rebuild
        self.notices: list[str] = []
        self.staff_left = 0
        self.pending: list[Callable[[], None]] = []
        self.swaps = 0
        self.events: list[SessionEvent] = []

    def redraw(self, *, rebuild: bool = False) -> None:
        self.redraws.append(rebuild)

    def session_event(self, event: SessionEvent) -> None:
        self.events.append(event)

    def tell_channels(self) -> None:
        self.swaps += 1

    def stopped(self, reason: str) -> None:
        self.notices.append(reason)

    def close_clinician(self) -> None:
        self.staff_left += 1

    def later(self, callback: Callable[[], None]) -> None:
        self.pending.append(callback)

    def run_pending(self) -> None:
        pending, self.pending = self.pending, []
        for callback in pending:
            callback()


class Kiosk:
    """A controller on a store in ``data_dir``, with a simulated clock, as make_kiosk wires it."""

    def __init__(self, data_dir: Path, *, store: dict[str, Any] | None = None, **config: Any) -> None:
        """``store`` are Store.open's options (``owner``, ``wall``, ``lease_ttl_s``); ``config``
        overrides the configuration (``next_patient_after_s``)."""
        self.clock = SimClock()
        self.config = Config(
            data_dir=data_dir,
            familiarisation=False,
            timing={"attempt_window_s": ATTEMPT_S},
            **config,
        )
        self.store = Store.open(data_dir, **(store or {}))
        numbers = iter(range(1, 1000))
        self.sessions = SessionMaker(
            self.config,
            KioskParts.load(self.config),
            clock=self.clock,
            store=self.store,
            patient_ids=lambda: f"P-CTRL{next(numbers):02d}",
        )
        self.controller = KioskController(
            self.sessions.fresh(),
            store=self.store,
            fresh=self.sessions.fresh,
            resume=self.sessions.resume,
            visits=VisitDesk(self.sessions.fresh, walk_up=True),
        )
        self.drawn = Drawn()
        self.controller.attach(self.drawn)

    def to_next_deadline(self) -> None:
        deadline = self.controller.session.next_deadline()
        assert deadline is not None, "nothing is pending"
        self.clock.set(deadline)
        self.controller.drive(self.controller.session.poll)

    def start_and_open_the_first_question(self) -> None:
        self.controller.greet()
        self.controller.start_in("en")
        assert self.controller.session.phase is Phase.EXPLANATION
        self.controller.forward(ChannelInput(Channel.KEYBOARD, option=1, detail="key 1"))  # understood
        self.to_next_deadline()
        assert self.controller.session.current_attempt == 1

    def answer(self, option: int = 1) -> None:
        session = self.controller.session
        item = session.current_item
        assert item is not None, "no question is open"
        self.controller.forward(ChannelInput(Channel.KEYBOARD, option=option, detail=f"key {option}"))
        assert item.id in session.answers


@pytest.fixture
def kiosk(tmp_path: Path) -> Iterator[Kiosk]:
    made = Kiosk(tmp_path / "data")
    yield made
    made.store.close()


@contextmanager
def another_kiosk_process() -> Iterator[int]:
    """A real process standing in for another kiosk on the same data directory."""
    child = subprocess.Popen([sys.executable, "-c", "import sys; sys.stdin.read()"], stdin=subprocess.PIPE)
    try:
        yield child.pid
    finally:
        child.kill()
        child.wait(timeout=30)


def test_staff_starting_a_new_patient_abandon_the_test_and_the_next_one_is_welcomed(kiosk):
    kiosk.start_and_open_the_first_question()
    kiosk.answer()
    first = kiosk.controller.session

    kiosk.controller.start_new_session()

    second = kiosk.controller.session
    assert second is not first and second.phase is Phase.WELCOME and second.patient_id == "P-CTRL02"
    assert second.listening  # the welcome was said and is listened to: '…or say "English"'
    assert kiosk.drawn.staff_left == 1 and True in kiosk.drawn.redraws
    stored = kiosk.store.session(first.id)
    assert stored.status == "abandoned" and len(stored.answers) == 1
    assert not kiosk.store.holds(first.id)  # let go: another kiosk's staff may look at it
    events_before = len(kiosk.controller.events)
    first.poll()  # the old session publishes nothing the kiosk still follows
    assert len(kiosk.controller.events) == events_before


def test_the_next_patient_is_welcomed_once_the_end_screen_has_been_shown(tmp_path):
    kiosk = Kiosk(tmp_path / "data", next_patient_after_s=60)
    try:
        kiosk.start_and_open_the_first_question()
        first = kiosk.controller.session
        while not first.finished:
            if first.current_attempt is None:
                kiosk.to_next_deadline()
            else:
                kiosk.answer()
        assert kiosk.drawn.pending == []  # the end screen stays its 60 s
        kiosk.to_next_deadline()
        kiosk.drawn.run_pending()
        assert kiosk.controller.session is not first and kiosk.controller.session.phase is Phase.WELCOME
        assert kiosk.store.session(first.id).status == "finished"
    finally:
        kiosk.store.close()


def test_the_clinician_screens_hold_a_running_test_and_leave_one_the_patient_paused_as_it_is(kiosk):
    kiosk.start_and_open_the_first_question()
    session = kiosk.controller.session

    kiosk.controller.hold()
    assert session.paused and kiosk.controller.held_for_clinician
    assert session.next_deadline() is None  # nothing times out unseen under the staff screens
    kiosk.controller.release()
    assert not session.paused and not kiosk.controller.held_for_clinician and session.current_attempt == 1

    kiosk.controller.forward(ChannelInput(Channel.KEYBOARD, command=Command.PAUSE, detail="key p"))
    assert session.paused
    kiosk.controller.hold()
    assert not kiosk.controller.held_for_clinician
    kiosk.controller.release()
    assert session.paused  # the patient's pause is theirs to lift


def test_a_station_command_acts_on_the_running_test_and_end_welcomes_the_next_patient(kiosk):
    kiosk.start_and_open_the_first_question()
    session = kiosk.controller.session

    assert kiosk.controller.station_command({"kind": "person_away", "session_id": session.id}) == ("done", None)
    assert not session.snapshot().person_present
    refused = kiosk.controller.station_command({"kind": "end", "session_id": "someone-else"})
    assert refused == ("refused", "session someone-else is not the one running on this kiosk")
    assert kiosk.controller.session is session

    done = kiosk.controller.station_command({"kind": "end", "session_id": session.id, "by": "nurse Ana"})

    assert done == ("done", None)
    assert kiosk.controller.session is not session and kiosk.controller.session.phase is Phase.WELCOME
    stored = kiosk.store.session(session.id)
    assert stored.status == "abandoned"
    assert [e.detail for e in stored.log if e.kind == "abandoned"] == ["ended from the ward station by nurse Ana"]


def test_staff_continue_an_interrupted_test_here_but_not_over_one_in_progress(tmp_path):
    with another_kiosk_process() as gone:
        crashed = Kiosk(tmp_path / "data", store={"owner": Owner(pid=gone)})
        crashed.start_and_open_the_first_question()
        crashed.answer()
        interrupted = crashed.controller.session.id
    kiosk = Kiosk(tmp_path / "data")
    try:
        kiosk.controller.keep_session()  # the lease round finds the stopped kiosk's test
        assert [t.id for t in kiosk.controller.interrupted_tests()] == [interrupted]

        assert kiosk.controller.continue_test(interrupted) is None

        session = kiosk.controller.session
        assert session.id == interrupted and session.phase is not Phase.WELCOME and len(session.answers) == 1
        assert kiosk.drawn.staff_left == 1 and kiosk.store.holds(interrupted)
        assert kiosk.controller.continue_test(interrupted) == IN_PROGRESS
    finally:
        kiosk.store.close()
        crashed.store.close()


def test_a_test_another_kiosk_took_over_is_let_go_with_a_notice_naming_no_patient(tmp_path):
    now = [1_000_000.0]
    kiosk = Kiosk(tmp_path / "data", store={"wall": lambda: now[0], "lease_ttl_s": 30})
    try:
        kiosk.start_and_open_the_first_question()
        kiosk.answer()
        session = kiosk.controller.session
        kiosk.controller.keep_session()
        assert kiosk.drawn.notices == [] and kiosk.controller.session is session  # renewed: still ours
        now[0] += 31  # this kiosk froze past its lease; another kiosk's staff continue the test
        with another_kiosk_process() as other:
            elsewhere = Store.open(tmp_path / "data", owner=Owner(pid=other), wall=lambda: now[0], lease_ttl_s=30)
            assert elsewhere.interrupt_stale() == [session.id]
            elsewhere.continue_session(session.id)

            kiosk.controller.keep_session()

            (notice,) = kiosk.drawn.notices
            assert "another kiosk" in notice and session.patient_id not in notice
            assert kiosk.controller.session is not session and kiosk.controller.session.phase is Phase.WELCOME
            assert elsewhere.holds(session.id) and len(elsewhere.session(session.id).answers) == 1
            elsewhere.close()
    finally:
        kiosk.store.close()


def test_every_event_of_the_running_session_reaches_the_ui_in_order(kiosk):
    kiosk.start_and_open_the_first_question()
    assert kiosk.drawn.events == kiosk.controller.events
    assert [e.kind for e in kiosk.controller.events if isinstance(e, Prompt)][:1] == ["welcome"]
