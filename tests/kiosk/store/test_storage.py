"""Real SQLite storage: permissions, answers committed as they happen, crash safety with SIGKILL,
resuming an unfinished session, and stored traces that replay to the recorded metrics."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from kiosk.commands.replay import load_script, run_script
from kiosk.core.channels import Channel
from kiosk.core.clock import SimClock
from kiosk.core.session import AttemptOpened, Session
from kiosk.export.opening import trace_main
from kiosk.store.database import StorageError, Store, new_patient_id
from qos import Engine, load_trace
from tests.kiosk.core.helpers import MODEL, QUESTIONNAIRE, TIMING, Rig

ROOT = Path(__file__).resolve().parents[3]


def stored_rig(store: Store, **kwargs) -> Rig:
    clock = SimClock()
    session = Session(
        QUESTIONNAIRE,
        clock=clock,
        engine=Engine(MODEL),
        store=store,
        patient_id="P-TEST01",
        timing=TIMING,
        familiarisation=False,
        **kwargs,
    )
    rig = Rig(session, clock)
    session.subscribe(rig.events.append)
    return rig


def test_data_directory_and_database_files_are_private(tmp_path):
    old = os.umask(0o022)
    try:
        data = tmp_path / "data"
        store = Store.open(data)
        rig = stored_rig(store)
        rig.at(1)
        rig.session.start()
    finally:
        os.umask(old)
    assert data.stat().st_mode & 0o777 == 0o700
    files = sorted(data.iterdir())
    assert {f.name for f in files} >= {"kiosk.sqlite3", "kiosk.sqlite3-wal"}
    assert all(f.stat().st_mode & 0o777 == 0o600 for f in files)


def test_an_existing_open_directory_is_tightened(tmp_path):
    data = tmp_path / "data"
    data.mkdir(mode=0o755)
    os.chmod(data, 0o755)
    Store.open(data).close()
    assert data.stat().st_mode & 0o777 == 0o700


def test_wal_and_full_sync_are_on(tmp_path):
    store = Store.open(tmp_path)
    assert store._db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    assert store._db.execute("PRAGMA synchronous").fetchone()[0] == 2  # FULL


def test_each_answer_is_visible_to_another_connection_as_soon_as_it_is_recorded(tmp_path):
    store = Store.open(tmp_path)
    rig = stored_rig(store)
    rig.at(10)
    rig.session.start()
    rig.session.acknowledge()
    rig.run_until(25)
    rig.at(28)
    rig.answer(2, Channel.REMOTE)
    other = sqlite3.connect(tmp_path / "kiosk.sqlite3")
    rows = other.execute("SELECT item_id, option, points, attempt, channel, t FROM answers").fetchall()
    assert rows == [("feeding", 2, 5, 1, "remote", 28.0)]
    assert other.execute("SELECT status FROM sessions").fetchone() == ("running",)


def test_patient_ids_must_be_pseudonymous(tmp_path):
    store = Store.open(tmp_path)
    clock = SimClock()
    session = Session(QUESTIONNAIRE, clock=clock, engine=None, store=store, patient_id="Ann Smith")
    with pytest.raises(ValueError, match="not a pseudonymous id"):
        session.start()
    assert new_patient_id().startswith("P-") and new_patient_id() != new_patient_id()


CHILD = textwrap.dedent("""
    import sys
    from kiosk.core.channels import Channel, ChannelInput
    from kiosk.core.clock import SimClock
    from kiosk.core.questionnaire import load_questionnaire
    from kiosk.core.session import Session
    from kiosk.store.database import Store
    from qos import Engine, load_model

    store = Store.open(sys.argv[1])
    clock = SimClock()
    session = Session(load_questionnaire(), clock=clock, engine=Engine(load_model("clarc")), store=store,
                      patient_id="P-CRASH1", familiarisation=False,
                      timing={"attempt_window_s": 30, "between_questions_s": 15})
    clock.set(10)
    session.start()
    session.acknowledge()
    for option in (3, 1, 2, 2):
        while session.current_attempt is None:
            clock.set(session.next_deadline())
            session.poll()
        clock.advance(4)
        session.handle(ChannelInput(Channel.TOUCH, option=option))
        print("recorded", session.current_item.id, flush=True)
    # the fifth question is open when the power goes
    clock.set(session.next_deadline())
    session.poll()
    print("READY", session.id, flush=True)
    sys.stdin.read()
""")


@pytest.mark.slow
def test_sigkill_mid_session_loses_no_answer_and_the_session_resumes_at_the_first_unanswered(tmp_path):
    data = tmp_path / "data"
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(data)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, cwd=ROOT
    )
    recorded = []
    try:
        for line in child.stdout:
            if line.startswith("READY"):
                session_id = line.split()[1]
                break
            recorded.append(line.split()[1])
        else:
            pytest.fail("the child session never got ready")
        os.kill(child.pid, signal.SIGKILL)
    finally:
        child.wait(timeout=30)
    assert child.returncode == -signal.SIGKILL
    assert recorded == ["feeding", "bathing", "grooming", "dressing"]

    store = Store.open(data)
    (unfinished,) = store.unfinished_sessions()  # its kiosk process is gone: interrupted
    assert unfinished.id == session_id and unfinished.status == "interrupted"
    assert "stopped" in (unfinished.interrupted_reason or "")
    unfinished = store.continue_session(session_id)  # staff continue it on this kiosk
    assert [(a.item_id, a.option) for a in unfinished.answers] == [
        ("feeding", 3),
        ("bathing", 1),
        ("grooming", 2),
        ("dressing", 2),
    ]
    last_t = unfinished.trace[-1]["t"]

    clock = SimClock(start=500)
    engine = Engine(MODEL)
    session = Session.from_stored(QUESTIONNAIRE, unfinished, clock=clock, engine=engine, store=store, timing=TIMING)
    rig = Rig(session, clock)
    session.subscribe(rig.events.append)
    assert session.now() == last_t + 1
    session.start()
    session.acknowledge()
    rig.run_until(last_t + 1 + 15)
    first = rig.of(AttemptOpened)[0]
    assert (first.item_id, first.attempt) == ("bowels", 1)
    assert session.trace[-1] == {"t": last_t + 1, "set": {"PersonDetected": True, "TestState": "RESTARTED"}}
    for _ in range(6):
        rig.at(session.now() + 2)
        rig.answer(1)
        rig.run_until(session.now() + 15)
    rig.run_until(session.now() + 5)
    assert session.finished and session.score().complete
    again = store.session(session_id)
    assert again.status == "finished" and len(again.answers) == 10
    assert not store.unfinished_sessions()


@pytest.mark.slow  # a subprocess
def test_a_stored_trace_printed_by_kiosk_qos_trace_replays_to_the_recorded_metrics(tmp_path, capsys):
    store = Store.open(tmp_path / "data")
    result = run_script(load_script(ROOT / "recordings/patients/barthel5.yaml"), store=store)
    stored = store.session(result.session.id)
    assert trace_main([result.session.id[:5], "--data-dir", str(tmp_path / "data")]) == 0
    path = tmp_path / "trace.yaml"
    path.write_text(capsys.readouterr().out)
    trace = load_trace(path)
    assert [e.to_dict() for e in trace.events] == [e.to_dict() for e in result.trace.events]

    # the real `python -m qos replay` on the printed trace gives the session's last recorded metrics
    out = subprocess.run(
        [sys.executable, "-m", "qos", "replay", str(path), "--json"],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    replayed = json.loads(out.stdout)
    for name, value in stored.metrics[-1].metrics.items():
        assert replayed["metrics"][name]["last"] == pytest.approx(value, abs=1e-12)
    # and a fresh engine fed the trace gives every recorded sample, batch by batch
    engine = Engine(MODEL)
    for (t, values, emitted), sample in zip(trace.batches(), stored.metrics, strict=True):
        update = engine.update(float(t), set=values, emit=emitted)
        assert (float(t), update.metrics, tuple(update.fired)) == (sample.t, dict(sample.metrics), sample.fired)


def test_kiosk_qos_trace_of_an_unknown_session_is_exit_2(tmp_path, capsys):
    Store.open(tmp_path).close()
    assert trace_main(["nope", "--data-dir", str(tmp_path)]) == 2
    assert capsys.readouterr().err.strip() == "kiosk qos trace: no session 'nope'"


def test_the_store_keeps_the_session_log_and_not_answered_questions(tmp_path):
    store = Store.open(tmp_path)
    rig = stored_rig(store)
    rig.at(10)
    rig.session.start(answered_by="caregiver")
    rig.session.choose_language("fr")
    rig.session.acknowledge()
    rig.run_until(26)
    rig.session.pause()
    rig.at(30)
    rig.session.resume()
    rig.run_until(200)
    stored = store.session(rig.session.id)
    assert stored.not_answered == ("feeding", "bathing")
    assert stored.answered_by.value == "caregiver"
    assert [(e.kind, e.detail) for e in stored.log][:4] == [
        ("start", "answered by caregiver"),
        ("language", "fr"),
        ("pause", ""),
        ("resume", ""),
    ]
    assert stored.timing["attempt_window_s"] == 30
    assert [s.id for s in store.sessions()] == [rig.session.id]


def test_kiosk_qos_trace_to_an_unwritable_file_is_one_line_and_exit_2(tmp_path, capsys):
    with Store.open(tmp_path / "data") as store:
        result = run_script(load_script(ROOT / "recordings/patients/barthel5.yaml"), store=store)
    target = tmp_path / "missing" / "trace.yaml"
    assert trace_main([result.session.id, "--data-dir", str(tmp_path / "data"), "-o", str(target)]) == 2
    assert capsys.readouterr().err == f"kiosk qos trace: cannot write {target}: No such file or directory\n"


def test_reading_tools_refuse_a_missing_data_directory_or_database_and_create_nothing(tmp_path, capsys):
    from kiosk.commands.results import main as results_main

    typo = tmp_path / "typo"
    assert results_main(["--data-dir", str(typo)]) == 2
    assert capsys.readouterr().err == f"kiosk results: no data directory {typo}\n"
    assert trace_main(["abc", "--data-dir", str(typo)]) == 2
    assert capsys.readouterr().err == f"kiosk qos trace: no data directory {typo}\n"
    assert not typo.exists()
    empty = tmp_path / "empty"
    empty.mkdir()
    assert results_main(["--data-dir", str(empty)]) == 2
    assert capsys.readouterr().err == (
        f"kiosk results: no session database in {empty} (expected kiosk.sqlite3; nothing stored there)\n"
    )
    assert list(empty.iterdir()) == []
    with pytest.raises(StorageError, match="no data directory"):
        Store.open(typo, create=False)


def test_an_answer_and_its_qos_context_are_committed_together(tmp_path):
    """A crash between two commits would keep an answer without the evidence it gave the QoS engine;
    the operation is one transaction, so another reader sees both or neither."""
    store = Store.open(tmp_path / "data")
    seen_mid_operation: list[tuple[int, int]] = []

    def committed() -> tuple[int, int]:
        with sqlite3.connect(store.path) as other:
            answers = other.execute("SELECT COUNT(*) FROM answers").fetchone()[0]
            answered = other.execute(
                "SELECT COUNT(*) FROM contexts WHERE sets LIKE '%FirstAttemptAnswered%'"
            ).fetchone()[0]
        return answers, answered

    class Observed(Engine):
        """The real engine; it also looks at the database while the answer's batch is applied."""

        def update(self, t, set=None, emit=None):
            if set and "FirstAttemptAnswered" in set:
                seen_mid_operation.append(committed())
            return super().update(t, set=set, emit=emit)

    clock = SimClock()
    session = Session(
        QUESTIONNAIRE,
        clock=clock,
        engine=Observed(MODEL),
        store=store,
        patient_id="P-TEST01",
        timing=TIMING,
        familiarisation=False,
    )
    rig = Rig(session, clock)
    session.start()
    session.acknowledge()
    rig.run_until(session.now() + 15)
    rig.answer(2)
    assert seen_mid_operation == [(0, 0)]  # neither is visible before the operation ends
    assert committed() == (1, 1)  # both are, once it has


def test_an_operation_that_writes_nothing_takes_no_write_lock(tmp_path):
    """The UI polls the attempt clock ten times a second; a poll with nothing due must not lock
    the database against another writer (say `kiosk replay --data-dir` on the same kiosk)."""
    store = Store.open(tmp_path / "data")
    rig = stored_rig(store)
    rig.session.start()
    with store.transaction():
        rig.session.poll()  # nothing is due
        with sqlite3.connect(store.path, timeout=0) as other:
            other.execute("INSERT INTO patients (id, created_at) VALUES ('P-OTHER1', 'now')")  # not locked out
