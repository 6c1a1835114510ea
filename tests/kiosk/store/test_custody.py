"""One kiosk per session, interrupted and simulated sessions: real SQLite, real processes as owners.

A lease's owner is a process; "another kiosk" here is a store whose owner is a real child process,
so its liveness is checked the way the kiosk checks it (the process exists on this host or not)."""

from __future__ import annotations

import subprocess
import sys
from contextlib import contextmanager
from datetime import UTC

import pytest

from kiosk.store.database import Store
from kiosk.store.lease import Owner, SessionTaken

TIMING = {"attempt_window_s": 30}


@contextmanager
def process():
    """A real process standing in for another kiosk; killed (and reaped) on exit."""
    child = subprocess.Popen([sys.executable, "-c", "import sys; sys.stdin.read()"], stdin=subprocess.PIPE)
    try:
        yield child
    finally:
        child.kill()
        child.wait(timeout=30)


def create(
    store: Store, session_id: str = "s1", patient: str = "P-AAAAAA", started_at: str = "2026-11-23T15:00:00+00:00"
) -> None:
    store.create_session(
        session_id=session_id,
        patient_id=patient,
        questionnaire_id="barthel",
        language="en",
        answered_by="patient",
        started_at=started_at,
        timing=TIMING,
    )


def answer(store: Store, item: str = "feeding", session_id: str = "s1") -> None:
    store.record_answer(
        session_id,
        item_id=item,
        option=2,
        points=5,
        attempt=1,
        channel="touch",
        answered_by="patient",
        t=1.0,
        at="2026-11-23T15:00:01+00:00",
    )


def test_a_session_held_by_a_running_kiosk_is_neither_written_nor_offered_elsewhere(tmp_path):
    with process() as other_kiosk:
        first = Store.open(tmp_path, owner=Owner(pid=other_kiosk.pid))
        create(first)
        answer(first, "feeding")
        second = Store.open(tmp_path)
        assert second.unfinished_sessions() == []  # running, and its kiosk runs
        with pytest.raises(SessionTaken, match=rf"open on another kiosk, .*process {other_kiosk.pid}"):
            answer(second, "bathing")
        with pytest.raises(SessionTaken, match="open on another kiosk"):
            second.continue_session("s1")
        assert [a.item_id for a in second.session("s1").answers] == ["feeding"]  # nothing written
        other_kiosk.kill()
        other_kiosk.wait()
        # its kiosk is gone: interrupted, for staff to continue
        (interrupted,) = second.unfinished_sessions()
        assert interrupted.status == "interrupted"
        assert interrupted.interrupted_reason == f"its kiosk {first.owner.describe()} stopped"
        continued = second.continue_session("s1")
        assert continued.status == "running" and [a.item_id for a in continued.answers] == ["feeding"]
        answer(second, "bathing")
        # the first kiosk's store (its process is gone; its object lingers here) can no longer write
        with pytest.raises(SessionTaken):
            answer(first, "grooming")
        assert [a.item_id for a in second.session("s1").answers] == ["feeding", "bathing"]


def test_of_two_kiosks_continuing_the_same_test_one_wins_and_the_other_is_told(tmp_path):
    with process() as gone:
        crashed = Store.open(tmp_path, owner=Owner(pid=gone.pid))
        create(crashed)
    with process() as other_kiosk:
        a = Store.open(tmp_path, owner=Owner(pid=other_kiosk.pid))
        b = Store.open(tmp_path)
        a.continue_session("s1")
        with pytest.raises(SessionTaken, match="open on another kiosk"):
            b.continue_session("s1")
        assert a.holds("s1") and not b.holds("s1")


def test_a_lease_not_renewed_lapses_and_one_renewed_holds(tmp_path):
    now = [1_000_000.0]
    with process() as other_kiosk:
        frozen = Store.open(tmp_path, owner=Owner(pid=other_kiosk.pid), wall=lambda: now[0], lease_ttl_s=30)
        create(frozen)
        me = Store.open(tmp_path, wall=lambda: now[0], lease_ttl_s=30)
        now[0] += 25
        frozen.renew()
        now[0] += 25  # 50 s after it was taken, 25 after the renewal: it holds
        assert me.interrupt_stale() == []
        now[0] += 6  # 31 s since the renewal: a frozen or unreachable kiosk
        assert me.interrupt_stale() == ["s1"]
        assert "stopped answering" in (me.session("s1").interrupted_reason or "")


def test_a_session_older_than_the_limit_is_interrupted_even_if_its_kiosk_runs(tmp_path):
    """A test left open for hours (the patient walked away) is not the next visitor's to finish."""
    started = 1_800_000_000.0
    now = [started + 2 * 3600 + 1]
    store = Store.open(tmp_path, wall=lambda: now[0], interrupt_after_s=2 * 3600)
    from datetime import datetime

    create(store, started_at=datetime.fromtimestamp(started, UTC).isoformat())
    assert store.interrupt_stale() == ["s1"]
    assert store.session("s1").interrupted_reason == "not finished within 120 minutes"
    with pytest.raises(SessionTaken, match="no longer held by this kiosk: it is interrupted"):
        answer(store)


def test_closing_the_kiosk_interrupts_its_running_session_and_leaves_finished_ones_alone(tmp_path):
    store = Store.open(tmp_path)
    create(store, "s1")
    create(store, "s2", patient="P-BBBBBB")
    store.finish_session("s2", finished_at="2026-11-23T15:10:00+00:00", total=5, complete=False, band=None)
    store.close()
    with Store.open(tmp_path) as again:
        statuses = {s.id: (s.status, s.interrupted_reason) for s in again.sessions()}
        assert statuses == {"s1": ("interrupted", "its kiosk was closed"), "s2": ("finished", None)}
        assert again._db.execute("SELECT COUNT(*) FROM leases").fetchone() == (0,)


def test_simulated_sessions_are_marked_and_never_offered(tmp_path):
    with process() as replay:
        replayed = Store.open(tmp_path, simulated=True, owner=Owner(pid=replay.pid))
        create(replayed, "sim1", patient="TB-0001")
    kiosk = Store.open(tmp_path)
    assert kiosk.unfinished_sessions() == []
    (summary,) = kiosk.sessions()
    assert summary.simulated and summary.status == "interrupted" and summary.label == "interrupted, simulated"
    assert kiosk.session("sim1").simulated
    with pytest.raises(ValueError, match="simulated"):
        kiosk.continue_session("sim1")


def test_an_exception_inside_a_transaction_keeps_none_of_its_writes(tmp_path):
    store = Store.open(tmp_path)
    create(store)
    with pytest.raises(KeyboardInterrupt), store.transaction():
        answer(store)
        store.record_context("s1", t=1.0, set={"FirstAttemptAnswered": True}, emit=[])
        raise KeyboardInterrupt
    stored = store.session("s1")
    assert stored.answers == () and stored.trace == ()
    answer(store)  # the store is usable afterwards
    assert len(store.session("s1").answers) == 1


def test_a_kiosk_leaves_a_running_replays_session_alone_whatever_its_simulated_start(tmp_path):
    """`kiosk replay --data-dir` beside a running kiosk: the replay's session starts on the simulated
    clock (2026-01-01), so its age is no reason to interrupt it while the replay runs."""
    with process() as replay:
        replayed = Store.open(tmp_path, simulated=True, owner=Owner(pid=replay.pid))
        create(replayed, "sim1", patient="TB-0001", started_at="2026-01-01T00:00:05+00:00")
        kiosk = Store.open(tmp_path, interrupt_after_s=2 * 3600)
        assert kiosk.interrupt_stale() == []
        answer(replayed, session_id="sim1")  # the replay goes on
    assert kiosk.interrupt_stale() == ["sim1"]  # once it is gone, its session is interrupted
