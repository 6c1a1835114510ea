"""Half-written answers (issue 10 part 7): an operation cut short -- an exception, or Ctrl-C as a
real SIGINT -- at the worst point (the answer and its context batch are written, the metrics not
yet) stores none of it, and listeners never hear of it."""

from __future__ import annotations

import sqlite3
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from kiosk.core.clock import SimClock
from kiosk.core.session import AnswerRecorded, Session
from kiosk.store.database import Store
from qos import Engine
from tests.kiosk.core.helpers import MODEL, QUESTIONNAIRE, TIMING, Rig, at_first_question

ROOT = Path(__file__).resolve().parents[3]


def counts(path: Path) -> tuple[int, int, int]:
    """Answers, answer context batches and metric samples another connection sees."""
    with sqlite3.connect(path) as other:
        return (
            other.execute("SELECT COUNT(*) FROM answers").fetchone()[0],
            other.execute("SELECT COUNT(*) FROM contexts WHERE sets LIKE '%AttemptAnswered\": true%'").fetchone()[0],
            other.execute("SELECT COUNT(*) FROM metric_samples").fetchone()[0],
        )


class Interrupting(Engine):
    """The real engine, cut short while it takes the answer's batch: by then the answer and the
    batch are written in the transaction, the metrics are not."""

    def __init__(self, model, error: BaseException) -> None:
        super().__init__(model)
        self.error: BaseException | None = error

    def update(self, t, set=None, emit=None):
        if self.error is not None and set and "FirstAttemptAnswered" in set:
            error, self.error = self.error, None
            raise error
        return super().update(t, set=set, emit=emit)


@pytest.mark.parametrize("error", [KeyboardInterrupt(), RuntimeError("engine failed")], ids=["ctrl-c", "exception"])
def test_an_answer_cut_short_before_its_metrics_stores_nothing_of_it(tmp_path, error):
    store = Store.open(tmp_path / "data")
    rig = at_first_question(store, engine=Interrupting(MODEL, error))
    session = rig.session
    metrics_before = counts(store.path)[2]
    with pytest.raises(type(error)):
        rig.answer(2)
    assert counts(store.path) == (0, 0, metrics_before)  # neither the answer nor half its evidence
    assert not rig.of(AnswerRecorded)  # and nobody was told of it
    stored = store.session(session.id)
    assert stored.answers == () and all("FirstAttemptAnswered" not in (e.get("set") or {}) for e in stored.trace)
    # the next operation on the same store commits normally
    rig.session.poll()
    store.record_event(session.id, t=session.now(), kind="note", detail="after the interruption")
    assert store.session(session.id).log[-1].kind == "note"


SIGINT_CHILD = textwrap.dedent("""
    import os, signal, sys, time
    from kiosk.core.channels import Channel, ChannelInput
    from kiosk.core.clock import SimClock
    from kiosk.core.questionnaire import load_questionnaire
    from kiosk.core.session import Session
    from kiosk.store.database import Store
    from qos import Engine, load_model

    class CtrlC(Engine):
        '''Presses Ctrl-C (a real SIGINT to this process) while the answer's batch is applied.'''
        def update(self, t, set=None, emit=None):
            if set and "FirstAttemptAnswered" in set:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(5)  # the signal's KeyboardInterrupt lands here, mid-operation
            return super().update(t, set=set, emit=emit)

    # Python's own Ctrl-C handler, as in a kiosk started from a terminal (a shell that started the
    # tests in the background hands its children SIGINT ignored, and Python then keeps it so)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    store = Store.open(sys.argv[1])
    clock = SimClock()
    session = Session(load_questionnaire(), clock=clock, engine=CtrlC(load_model("clarc")), store=store,
                      patient_id="P-CTRLC1", familiarisation=False,
                      timing={"attempt_window_s": 30, "between_questions_s": 15})
    clock.set(10)
    session.start()
    session.acknowledge()
    while session.current_attempt is None:
        clock.set(session.next_deadline())
        session.poll()
    print("ASKING", session.id, flush=True)
    clock.advance(4)
    session.handle(ChannelInput(Channel.TOUCH, option=2))
    print("STORED", flush=True)
""")


@pytest.mark.slow  # a subprocess
def test_a_real_ctrl_c_mid_answer_leaves_the_session_without_it_and_staff_continue_at_that_question(tmp_path):
    data = tmp_path / "data"
    child = subprocess.run(
        [sys.executable, "-c", SIGINT_CHILD, str(data)], capture_output=True, text=True, cwd=ROOT, timeout=120
    )
    assert child.returncode != 0 and "KeyboardInterrupt" in child.stderr
    lines = child.stdout.split()
    assert lines[0] == "ASKING" and "STORED" not in lines
    session_id = lines[1]
    store = Store.open(data)
    assert counts(store.path)[:2] == (0, 0)
    (interrupted,) = store.unfinished_sessions()  # its process is gone: for staff, not a patient
    assert interrupted.id == session_id and interrupted.answers == ()
    continued = Session.from_stored(
        QUESTIONNAIRE,
        store.continue_session(session_id),
        clock=SimClock(500),
        engine=Engine(MODEL),
        store=store,
        timing=TIMING,
    )
    rig = Rig(continued, continued.clock)
    continued.start()
    continued.acknowledge()
    rig.run_until(continued.now() + 15)
    assert continued.current_item.id == "feeding"  # asked again: nothing was stored of it
