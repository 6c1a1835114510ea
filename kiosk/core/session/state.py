"""What a session is and knows: the one mutable state its collaborators share, and the questions
about it that need nothing else (which item is open, what the policy asks of pace and voice).

Every collaborator of :class:`~kiosk.core.session.Session` receives this one object in its
constructor: the state lives in one place, so no collaborator needs to know the others to read it.
"""

from __future__ import annotations

from dataclasses import field
from typing import Any

from basis import record
from kiosk.core.adaptation import VOICE_OFF
from kiosk.core.channels import Channel
from kiosk.core.questionnaire import Item, PracticeQuestion, Questionnaire, Score, Timing
from kiosk.core.session.events import AnsweredBy, Phase, Prompt
from kiosk.core.session.snapshot import Answer


@record(frozen=False)
class Unconfirmed:
    """An answer heard but not stored yet, waiting for Yes or No."""

    option: int
    channel: Channel
    detail: str
    confidence: float | None
    #: what was left of the attempt's window when the confirmation was asked
    remaining: float
    #: a "yes" came too unsure to store the answer: the patient is asked to press Yes or No
    press: bool = False


@record(frozen=False)
class HeardCall:
    """A call for the doctor heard by voice, waiting for "Shall I call the nurse?" Yes or No."""

    #: what was heard, and how sure the recogniser was
    detail: str
    confidence: float | None
    #: the time-out pending when it was heard (kind, seconds left): put back once it is answered
    pending: tuple[str, float] | None
    #: "Shall I call the nurse?" as asked (the prompt's text), in the patient's language
    text: str = ""
    #: a spoken "yes" came too unsure: the patient is asked to press Yes or No
    press: bool = False
    #: the question as last published (asked again after a pause or the patient's return)
    prompt: Prompt | None = None


@record(frozen=False)
class OpenQuestion:
    """The question currently on screen: a scored item or a practice question."""

    practice: bool
    index: int
    attempt: int = 0
    #: None while open; "answered" or "not_answered" once over (it stays on screen until the next)
    outcome: str | None = None
    #: an answer heard but waiting for Yes or No before it is stored
    unconfirmed: Unconfirmed | None = None
    #: asked again after its answer was taken back: the new answer publishes no attempt context,
    #: and no answer in time leaves the question unanswered
    correcting: bool = False
    #: practice: the message that answered it ("practice_right"/"practice_wrong"), shown meanwhile
    feedback: str | None = None
    #: practice: the option the patient chose, shown chosen until the next question opens
    chosen: int | None = None


@record
class BatteryPlace:
    """Where a session stands in a visit's battery: the visit's id, its instrument's index and every
    instrument's id, in order. Logged at the start (``battery`` entry) so a continued test knows
    what comes after it."""

    visit_id: str
    index: int
    instruments: tuple[str, ...]

    def detail(self) -> str:
        """The ``battery`` log entry: ``<visit id> <index+1>/<count> <id>,<id>,...``."""
        return f"{self.visit_id} {self.index + 1}/{len(self.instruments)} {','.join(self.instruments)}"

    @classmethod
    def parse(cls, detail: str) -> BatteryPlace | None:
        """The place a ``battery`` log entry names (None for anything else)."""
        parts = detail.split(" ")
        if len(parts) != 3 or "/" not in parts[1]:
            return None
        number, _, count = parts[1].partition("/")
        ids = tuple(parts[2].split(","))
        if not (number.isdigit() and count.isdigit()) or int(count) != len(ids) or not 1 <= int(number) <= len(ids):
            return None
        return cls(parts[0], int(number) - 1, ids)

    @property
    def last(self) -> bool:
        return self.index == len(self.instruments) - 1


@record(frozen=False)
class SessionState:
    """One administration's state. The first fields are fixed when the session is made."""

    questionnaire: Questionnaire
    timing: Timing
    #: the session's id in the store and on the trace
    id: str
    patient_id: str
    #: the live adaptation policy (``kiosk.core.adaptation.Adaptation``), or None
    adaptation: Any
    language: str
    answered_by: AnsweredBy
    #: practice questions come before the explanation
    familiarisation: bool
    #: continuing a stored session (nothing new is created in the store)
    resuming: bool
    #: the session exists in the store (the log is written from then on)
    stored: bool
    #: a battery's later instrument: the start shows the rest screen before its explanation
    rest: bool = False
    answers: dict[str, Answer] = field(default_factory=dict)
    not_answered: list[str] = field(default_factory=list)
    phase: Phase = Phase.WELCOME
    #: the welcome prompt was published (see Session.welcome): listen for "start" until started
    greeted: bool = False
    open: OpenQuestion | None = None
    person_present: bool = True
    #: scored questions in a row that both attempts ran out on (an answer sets it back to 0)
    not_answered_run: int = 0
    #: that run reached the site's ``unattended_after``: the kiosk waits for a touch to go on
    unattended: bool = False
    #: whether voice in works on this kiosk (see Session.set_voice_available)
    voice_available: bool = True
    #: whether voice out works on this kiosk (see Session.set_voice_out_available)
    voice_out_available: bool = True
    #: ids of the practice questions skipped before they were shown
    practice_unasked: set[str] = field(default_factory=set)
    #: a call for the doctor heard by voice, waiting for Yes or No (see kiosk.core.session.calls)
    call: HeardCall | None = None
    #: the latest prompt published
    prompt: Prompt | None = None
    #: a repeated prompt is being given: TestState is REPEATING until anything else happens
    repeating: bool = False
    listening: bool = False
    score: Score | None = None

    @property
    def finished(self) -> bool:
        """The session reached the summary."""
        return self.phase is Phase.SUMMARY

    def started(self) -> bool:
        """Past the welcome and not yet at the summary."""
        return self.phase not in (Phase.WELCOME, Phase.SUMMARY)

    @property
    def current_item(self) -> Item | None:
        """The scored item on screen (see ``Session.current_item``)."""
        if self.open and not self.open.practice:
            return self.questionnaire.items[self.open.index]
        return None

    @property
    def current_attempt(self) -> int | None:
        """The open attempt's number, else None."""
        return self.open.attempt if self.open and self.open.outcome is None else None

    def question(self) -> Item | PracticeQuestion:
        """The open question: a scored item or a practice question."""
        assert self.open is not None
        if self.open.practice:
            return self.questionnaire.familiarisation[self.open.index]
        return self.questionnaire.items[self.open.index]

    def open_key(self) -> tuple[str, int]:
        """The open question's id and number."""
        assert self.open is not None
        if self.open.practice:
            return self.questionnaire.familiarisation[self.open.index].id, self.open.index + 1
        item = self.questionnaire.items[self.open.index]
        return item.id, item.number

    def next_item_index(self) -> int | None:
        """The first item the patient answers with neither an answer nor a "not answered" record
        (staff items, ``answered_by: staff``, are never asked: staff enter them afterwards)."""
        done = set(self.answers) | set(self.not_answered)
        items = self.questionnaire.items
        return next((i for i, item in enumerate(items) if item.id not in done and not item.staff), None)

    def patient_items(self) -> list[Item]:
        """The items asked at the kiosk, in order ("Question k of n" counts only these)."""
        return [item for item in self.questionnaire.items if not item.staff]

    def can_undo(self, timer_kind: str | None) -> bool:
        """The thank-you gap after a stored answer is running (``timer_kind``: the pending time-out)."""
        open_ = self.open
        return (
            self.phase is Phase.QUESTIONS
            and open_ is not None
            and not open_.practice
            and open_.outcome == "answered"
            and timer_kind in ("open", "finish")
            and self.questionnaire.items[open_.index].id in self.answers
        )

    def interlude(self, timer_kind: str | None) -> str | None:
        """What to show while the next question (or the summary) is being waited for."""
        if self.phase is Phase.FAMILIARISATION and timer_kind == "practice" and self.open is not None:
            return self.open.feedback  # "Well done." stays while the next practice question waits
        if self.phase is not Phase.QUESTIONS or timer_kind is None or not self.person_present:
            return None  # nobody is there to go on with: the one message is the away notice
        if timer_kind == "finish":
            return "last_question"
        if timer_kind != "open":
            return None
        if self.open is not None and self.open.outcome == "not_answered":
            return "not_answered"
        if self.open is None and not (self.answers or self.not_answered):
            return "first_question"
        return "next_question"

    def practice_skip_reason(self, question: PracticeQuestion) -> str | None:
        """Why ``question`` cannot be asked on this kiosk now, or None if it can."""
        if question.checks == "hear" and not self.voice_out_available:
            return "no voice out"
        return None

    # -- what the adaptation policy asks of the session ------------------------------------------

    def active_adaptations(self) -> frozenset[str]:
        return frozenset(self.adaptation.active) if self.adaptation is not None else frozenset()

    def voice_off(self) -> bool:
        """Whether an adaptation stopped listening for speech (voice_off, voice_room)."""
        return bool(VOICE_OFF & self.active_adaptations())

    def speech_rate(self) -> float:
        return self.adaptation.speech_rate if self.adaptation is not None else 1.0

    def attempt_window(self) -> float:
        """How long an attempt opened now waits: longer while ``longer_attempts`` is on."""
        factor = self.adaptation.attempt_factor if self.adaptation is not None else 1.0
        return self.timing.attempt_window_s * factor
