"""A battery in one visit, on a simulated clock with the real engine and a real store: the
instruments in order, one familiarisation, the rest screen between, pause / call doctor /
change-my-answer across the boundary, one QoS trace, a result per instrument, and a visit
continued after its kiosk stopped mid-second-instrument."""

from __future__ import annotations

import pytest

from kiosk.core.channels import Command
from kiosk.core.clock import SimClock
from kiosk.core.session import AnswerWithdrawn, Finished, Phase, PhaseChanged, Prompt, Session
from kiosk.core.session.battery import Battery, Instrument
from kiosk.store.database import Store
from qos import Engine
from tests.kiosk.battery_instruments import load_mini
from tests.kiosk.core.helpers import MODEL, QUESTIONNAIRE, TIMING, Rig


def battery(tmp_path, store=None, clock=None) -> Battery:
    mini = load_mini(tmp_path)
    return Battery(
        [Instrument(QUESTIONNAIRE), Instrument(mini)],
        make_engine=lambda model: Engine(MODEL),
        shared={"clock": clock or SimClock(), "store": store, "timing": TIMING},
    )


class Visit:
    """Drives a battery's sessions the way the controller does: the next one once one finishes."""

    def __init__(self, bat: Battery, **first) -> None:
        self.battery = bat
        self.sessions: list[Session] = []
        self.events: list = []
        self._follow(bat.first(patient_id="P-BAT01", familiarisation=True, **first))

    def _follow(self, session: Session) -> None:
        self.sessions.append(session)
        self.rig = Rig(session, session.clock, self.events)
        session.subscribe(self.events.append)

    @property
    def session(self) -> Session:
        return self.sessions[-1]

    def next_instrument(self) -> None:
        """The running instrument finished: the next one starts (the controller's step)."""
        after = self.battery.after(self.session)
        assert after is not None
        self._follow(after)
        after.start()

    def answer_all(self, option: int = 1) -> None:
        """Answer every remaining question of the running instrument, then let it finish."""
        while not self.session.finished:
            if self.session.current_attempt is not None:
                self.rig.answer(option)
            self.rig.run_until(self.session.now() + 16)


def through_first(visit: Visit) -> None:
    session = visit.session
    session.start()
    while session.phase is Phase.FAMILIARISATION:
        visit.rig.answer(visit.session.snapshot().practice.options[0].number)
        visit.rig.run_until(session.now() + 20)
    session.acknowledge()
    visit.answer_all()


def test_the_instruments_run_in_order_with_one_familiarisation_and_a_rest_between(tmp_path):
    visit = Visit(battery(tmp_path))
    through_first(visit)
    first = visit.sessions[0]
    assert first.finished and first.score().total == 0
    visit.next_instrument()
    second = visit.session
    assert second.phase is Phase.REST and second.questionnaire.id == "mini"
    rest = [p for p in visit.events if isinstance(p, Prompt) and p.key == "rest"][-1]
    assert rest.text == "Well done. Next: Two questions. Take a breath."
    assert [o.label for o in rest.options] == ["Continue"]
    visit.rig.answer(1)  # any number continues, as under the explanation
    assert second.phase is Phase.EXPLANATION
    second.acknowledge()
    visit.answer_all(option=2)
    phases = [e.phase for e in visit.events if isinstance(e, PhaseChanged)]
    assert phases.count(Phase.FAMILIARISATION) == 1
    assert phases.index(Phase.REST) > phases.index(Phase.SUMMARY)
    # one result per instrument, one visit: same patient, own ids, own totals
    finished = [e for e in visit.events if isinstance(e, Finished)]
    assert [f.score.total for f in finished] == [0, 10]  # Barthel all "unable", mini all option 2
    assert first.id != second.id and first.patient_id == second.patient_id == "P-BAT01"
    assert second.score().complete and second.score().max_total == 15
    assert visit.battery.after(second) is None


def test_one_trace_for_the_visit_and_the_engine_goes_on(tmp_path):
    visit = Visit(battery(tmp_path))
    through_first(visit)
    end_of_first = visit.sessions[0].now()
    visit.next_instrument()
    second = visit.session
    assert second.now() >= end_of_first  # session time goes on
    assert second.trace is visit.sessions[0].trace  # the same list: the visit's trace
    visit.rig.answer(1)
    second.acknowledge()
    visit.answer_all()
    states = [e["set"].get("TestState") for e in second.trace if "TestState" in e.get("set", {})]
    assert states.count("STARTED") == 2 and states.count("FINISHED") == 2
    times = [e["t"] for e in second.trace]
    assert times == sorted(times)
    assert second.engine is visit.sessions[0].engine


def test_pause_doctor_and_change_answer_work_on_the_rest_screen_and_after(tmp_path):
    visit = Visit(battery(tmp_path))
    through_first(visit)
    visit.next_instrument()
    second = visit.session
    visit.rig.command(Command.PAUSE)
    assert second.paused and second.phase is Phase.REST
    visit.rig.answer(1)  # paused: the number does not continue
    assert second.phase is Phase.REST
    visit.rig.command(Command.PAUSE)
    assert not second.paused
    visit.rig.command(Command.CALL_DOCTOR)
    assert second.halted
    second.clinician_continue()
    visit.rig.answer(1)
    assert second.phase is Phase.EXPLANATION
    second.acknowledge()
    visit.rig.run_until(second.now() + 16)
    visit.rig.answer(1)
    visit.rig.command(Command.UNDO)  # "change my answer" in the thank-you gap
    assert visit.rig.of(AnswerWithdrawn) and "feeding" not in second.answers
    visit.answer_all(option=2)
    assert second.answers["feeding"].option == 2


def test_a_visit_stopped_mid_second_instrument_continues_there_then_nothing_more(tmp_path):
    data = tmp_path / "data"
    store = Store.open(data)
    visit = Visit(battery(tmp_path, store=store))
    through_first(visit)
    visit.next_instrument()
    second = visit.session
    visit.rig.answer(1)
    second.acknowledge()
    visit.rig.run_until(second.now() + 16)
    visit.rig.answer(2)
    visit.rig.run_until(second.now() + 16)  # feeding stored, bathing open: the kiosk stops
    trace_before = list(second.trace)
    store.release(second.id, "the kiosk stopped")
    store.close()

    store = Store.open(data)
    (unfinished,) = store.unfinished_sessions()
    assert unfinished.id == second.id and Battery.place_of(unfinished).index == 1
    stored = store.continue_session(second.id)
    first_stored = store.session(visit.sessions[0].id)
    assert first_stored.status == "finished" and first_stored.questionnaire_id == "barthel"
    again = battery(tmp_path, store=store, clock=SimClock(start=900))
    again.visit_id = Battery.place_of(stored).visit_id
    resumed = again.resume(stored, before=[first_stored])
    assert resumed.trace[: len(trace_before)] == trace_before  # the visit's trace goes on
    rig = Rig(resumed, resumed.clock)
    resumed.subscribe(rig.events.append)
    resumed.start()
    assert resumed.phase is Phase.EXPLANATION  # no rest screen again, no practice
    resumed.acknowledge()
    rig.run_until(resumed.now() + 16)
    assert resumed.current_item.id == "bathing"
    rig.answer(1)
    rig.run_until(resumed.now() + 30)
    assert resumed.finished and again.after(resumed) is None
    assert store.session(second.id).status == "finished"
    assert resumed.score().total == 5 + 0


@pytest.mark.parametrize("detail", ["", "x 1/2 a", "x 3/2 a,b", "x one/2 a,b"])
def test_a_malformed_battery_entry_is_no_place(detail):
    from kiosk.core.session.state import BatteryPlace

    assert BatteryPlace.parse(detail) is None


def test_an_instrument_with_its_own_model_gets_its_own_engine_and_trace(tmp_path):
    from kiosk.core.qos_model import load_kiosk_model

    models = {None: MODEL, "kiosk_pace": load_kiosk_model("kiosk_pace")}
    bat = Battery(
        [Instrument(QUESTIONNAIRE), Instrument(load_mini(tmp_path), "kiosk_pace")],
        make_engine=lambda name: Engine(models[name]),
        shared={"clock": SimClock(), "timing": TIMING},
    )
    visit = Visit(bat)
    through_first(visit)
    visit.next_instrument()
    first, second = visit.sessions
    assert second.engine is not first.engine and second.engine.model is models["kiosk_pace"]
    assert second.trace is not first.trace  # one trace per model
    assert second.trace[0]["t"] >= first.trace[-1]["t"]  # on the visit's one session time
    assert second.trace[0]["set"]["TestState"] == "STARTED"
