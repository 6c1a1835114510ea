"""Building blocks for the session tests: a real session on a simulated clock with the real engine."""

from __future__ import annotations

from dataclasses import dataclass, field

from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.clock import SimClock
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import Session, SessionEvent
from qos import Engine, load_model

QUESTIONNAIRE = load_questionnaire()
MODEL = load_model("clarc")
#: the test-bench timing: easy round numbers to reason about
TIMING = {
    "attempt_window_s": 30,
    "between_questions_s": 15,
    "resume_grace_s": 10,
    "person_back_grace_s": 5,
    "closing_s": 5,
}


@dataclass
class Rig:
    """A session, its clock and everything it published."""

    session: Session
    clock: SimClock
    events: list[SessionEvent] = field(default_factory=list)

    def of(self, kind: type) -> list:
        """The events of one type, in order."""
        return [e for e in self.events if isinstance(e, kind)]

    def at(self, t: float) -> None:
        """Move to session time ``t``, firing every time-out due strictly before it."""
        target = self.session._origin + t  # clock time of session time t
        while (d := self.session.next_deadline()) is not None and d < target:
            self.clock.set(d)
            self.session.poll()
        self.clock.set(target)

    def run_until(self, t: float) -> None:
        """Like :meth:`at`, then also fire what is due exactly at ``t``."""
        self.at(t)
        self.session.poll()

    def answer(self, option: int, channel: Channel = Channel.TOUCH) -> None:
        """The patient chooses ``option`` now."""
        self.session.handle(ChannelInput(channel, option=option))

    def command(self, command: Command, channel: Channel = Channel.TOUCH) -> None:
        """The patient gives ``command`` now."""
        self.session.handle(ChannelInput(channel, command=command))


def make_rig(
    *, familiarisation: bool = False, timing: dict | None = None, language: str = "en", engine: bool = True, **kwargs
) -> Rig:
    """A fresh session at clock 0 with the real QoS engine."""
    clock = SimClock()
    session = Session(
        QUESTIONNAIRE,
        clock=clock,
        engine=Engine(MODEL) if engine else None,
        patient_id="T-0001",
        language=language,
        timing=timing or TIMING,
        familiarisation=familiarisation,
        **kwargs,
    )
    rig = Rig(session, clock)
    session.subscribe(rig.events.append)
    return rig


def started(**kwargs) -> Rig:
    """A session started at t=10 with the explanation acknowledged at once: Q1 opens at 25."""
    rig = make_rig(**kwargs)
    rig.at(10)
    rig.session.start()
    if rig.session.phase.value == "explanation":
        rig.session.acknowledge()
    return rig


def at_first_question(store, engine=None, patient_id: str = "P-TEST01") -> Rig:
    """A stored session (the real engine unless ``engine`` is given) started and explained, with
    its first question open."""
    clock = SimClock()
    session = Session(
        QUESTIONNAIRE,
        clock=clock,
        engine=engine or Engine(MODEL),
        store=store,
        patient_id=patient_id,
        timing=TIMING,
        familiarisation=False,
    )
    rig = Rig(session, clock)
    session.subscribe(rig.events.append)
    session.start()
    session.acknowledge()
    rig.run_until(session.now() + 15)
    return rig
