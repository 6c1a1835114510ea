"""The controller through a battery, without Pilot: the next instrument starts when one
finishes, an ordered visit runs the order's instruments in its order, and a test interrupted
mid-instrument continues there and then goes on with the remaining instruments."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from kiosk.config import Config, InstrumentChoice
from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.clock import SimClock
from kiosk.core.session import Phase
from kiosk.core.session.battery import Battery
from kiosk.core.visits import Order, VisitDesk
from kiosk.store.database import Store
from kiosk.ui.compose import KioskParts, SessionMaker
from kiosk.ui.controller import KioskController
from tests.kiosk.battery_instruments import write_mini

from .test_controller import Drawn


class BatteryKiosk:
    """A controller wired as make_kiosk wires it, configured with the Barthel then a short one."""

    def __init__(self, tmp_path: Path, mini_model: str | None = None, **store: Any) -> None:
        mini = write_mini(tmp_path)
        self.clock = SimClock()
        self.config = Config(
            data_dir=tmp_path / "data",
            familiarisation=False,
            instruments=(InstrumentChoice("barthel"), InstrumentChoice(str(mini), mini, mini_model)),
        )
        self.store = Store.open(self.config.data_dir, **store)
        self.maker = SessionMaker(self.config, KioskParts.load(self.config), clock=self.clock, store=self.store)
        self.controller = KioskController(
            self.maker.fresh(),
            store=self.store,
            fresh=self.maker.fresh,
            resume=self.maker.resume,
            after=self.maker.after,
            visits=VisitDesk(self.maker.fresh, walk_up=True),
        )
        self.drawn = Drawn()
        self.controller.attach(self.drawn)

    def key(self, option: int) -> None:
        self.controller.forward(ChannelInput(Channel.KEYBOARD, option=option, detail=f"key {option}"))
        self.drawn.run_pending()

    def next_deadline(self) -> None:
        self.clock.set(self.controller.session.next_deadline())
        self.controller.drive(self.controller.session.poll)
        self.drawn.run_pending()

    def answer_all(self) -> None:
        session = self.controller.session
        while not session.finished:
            self.next_deadline()
            if session.current_attempt is not None:
                self.key(1)


def test_the_controller_starts_the_next_instrument_on_its_rest_screen(tmp_path):
    kiosk = BatteryKiosk(tmp_path)
    controller = kiosk.controller
    controller.start_in("en")
    kiosk.key(1)  # the explanation understood
    first = controller.session
    kiosk.answer_all()
    second = controller.session
    assert first.finished and second is not first
    assert (second.questionnaire.id, second.phase) == ("mini", Phase.REST)
    kiosk.key(1)  # Continue
    kiosk.key(1)  # the explanation understood
    kiosk.answer_all()
    assert controller.session is second and second.finished  # the end screen stays after the last
    assert [kiosk.store.session(s.id).status for s in (first, second)] == ["finished", "finished"]


def test_an_order_runs_its_instruments_in_its_order(tmp_path):
    kiosk = BatteryKiosk(tmp_path)
    kiosk.controller.order_started(Order("O-1", "PAT-0042", ("mini", "barthel"), "en", "patient"))
    first = kiosk.controller.session
    assert first.questionnaire.id == "mini" and first.battery.instruments == ("mini", "barthel")
    kiosk.key(1)
    kiosk.answer_all()
    second = kiosk.controller.session
    assert second.questionnaire.id == "barthel" and second.patient_id == "PAT-0042" and second.visit == "order O-1"


def test_a_test_interrupted_in_the_first_instrument_continues_then_the_next_follows(tmp_path):
    kiosk = BatteryKiosk(tmp_path)
    kiosk.controller.start_in("en")
    kiosk.key(1)
    first = kiosk.controller.session
    for _ in range(3):  # three answers, then the kiosk stops
        kiosk.next_deadline()
        kiosk.key(2)
    kiosk.store.release(first.id, "the kiosk stopped")
    kiosk.store.close()

    again = BatteryKiosk(tmp_path)  # a kiosk started again on the same data directory
    assert again.controller.continue_test(first.id) is None
    resumed = again.controller.session
    assert resumed.id == first.id and len(resumed.answers) == 3
    assert Battery.place_of(again.store.session(first.id)).index == 0
    again.key(1)  # the explanation again
    again.answer_all()
    nxt = again.controller.session
    assert nxt is not resumed and (nxt.questionnaire.id, nxt.phase) == ("mini", Phase.REST)
    assert nxt.patient_id == resumed.patient_id and nxt.trace is resumed.trace
    assert again.store.session(first.id).status == "finished" and len(again.store.session(first.id).answers) == 10


def test_a_test_of_a_visit_this_kiosk_no_longer_gives_continues_on_its_instruments_own_qos_model(tmp_path):
    kiosk = BatteryKiosk(tmp_path, mini_model="kiosk_pace")
    kiosk.controller.order_started(Order("O-2", "PAT-0043", ("mini",), "en", "patient"))  # mini alone
    started = kiosk.controller.session
    assert started.engine.model.name == "KioskPace"  # kiosk_pace.roqme
    kiosk.key(1)
    kiosk.next_deadline()
    kiosk.key(2)
    kiosk.store.release(started.id, "the kiosk stopped")
    kiosk.store.close()

    again = BatteryKiosk(tmp_path, mini_model="kiosk_pace")  # gives barthel then mini: not that visit
    assert again.controller.continue_test(started.id) is None
    resumed = again.controller.session
    assert (resumed.id, resumed.questionnaire.id) == (started.id, "mini")
    assert resumed.engine.model.name == "KioskPace"  # not the battery's first instrument's (clarc)
