"""The state a screen renders: the recorded answers and a frozen picture of the session."""

from __future__ import annotations

from collections.abc import Mapping

from basis import record
from kiosk.core.channels import Channel
from kiosk.core.questionnaire import Item, PracticeQuestion, Score
from kiosk.core.session.events import AnsweredBy, Phase, Prompt


@record
class Answer:
    """A recorded answer to a scored item."""

    item_id: str
    option: int
    points: int
    attempt: int
    channel: Channel
    answered_by: AnsweredBy
    t: float
    detail: str = ""


@record
class Snapshot:
    """Everything a screen needs to draw the session at one moment."""

    phase: Phase
    language: str
    #: the scored item being asked (None outside questions or between them)
    item: Item | None
    #: 1-based number of that item, and how many there are ("Question k of n")
    number: int | None
    count: int
    #: the practice question being asked during familiarisation
    practice: PracticeQuestion | None
    attempt: int | None
    #: seconds left on the open attempt (frozen while paused, halted or the person is away)
    remaining: float | None
    paused: bool
    halted: bool
    person_present: bool
    listening: bool
    adaptations: frozenset[str]
    speech_rate: float
    answers: Mapping[str, Answer]
    not_answered: tuple[str, ...]
    score: Score | None
    #: the latest prompt published (question, practice or message; None before the first), so a
    #: screen rebuilt later can show what was last said without having kept the event
    prompt: Prompt | None = None
    #: during the gap before a question (or the summary) opens, the message to show meanwhile so
    #: the screen is never empty: "first_question", "next_question", "not_answered" or
    #: "last_question" (a questionnaire message name, or a screen word); None outside a gap
    interlude: str | None = None
    #: "Practice k of n" during familiarisation, counting only the practice questions asked here
    #: (a hearing check skipped without voice out is not counted); None outside a practice question
    practice_number: int | None = None
    practice_count: int = 0
    #: the option heard while "I heard: ... Is that right?" waits for Yes or No (the prompt has
    #: the question and the two options); None otherwise
    confirming: int | None = None
    #: "Change my answer" can be offered: the thank-you gap after an answer is running
    can_undo: bool = False
    #: questions in a row went unanswered: the kiosk waits for a touch ("Touch the screen to go on")
    unattended: bool = False
    #: "Shall I call the nurse?" (its text) while a call heard by voice waits for Yes or No
    #: (options 1 and 2); None otherwise
    calling: str | None = None
    #: the option chosen for the practice question on screen (shown chosen, as a scored answer
    #: is, until the next question opens); None before an answer and outside practice
    practice_chosen: int | None = None
    #: (k, n): this instrument is part k of the n of its visit's battery ("Part 2 of 3" between
    #: instruments); None for a visit of one instrument
    part: tuple[int, int] | None = None
