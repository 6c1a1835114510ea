"""What a session publishes and the words it uses for it: phases, who answers, why an input was
ignored, and the small frozen events listeners receive (``t`` is seconds since the session was
created, the QoS time)."""

from __future__ import annotations

from collections.abc import Mapping
from enum import Enum
from typing import Any

from basis import record
from kiosk.core.channels import Channel, ChannelInput, PresenceSource
from kiosk.core.questionnaire import Score

# Vocabulary


class Phase(str, Enum):
    """Where the session is."""

    WELCOME = "welcome"
    FAMILIARISATION = "familiarisation"
    EXPLANATION = "explanation"
    #: between two instruments of a battery: "Well done. Next: <title>. Take a breath." (Continue)
    REST = "rest"
    QUESTIONS = "questions"
    SUMMARY = "summary"


class AnsweredBy(str, Enum):
    """Who gives the answers; the Barthel index accepts self-report and a proxy's report."""

    PATIENT = "patient"
    RELATIVE = "relative"
    CAREGIVER = "caregiver"
    #: staff, for the items an instrument marks ``answered_by: staff`` (never a whole session's)
    STAFF = "staff"


class IgnoreReason(str, Enum):
    """Why an input did not change anything (published with :class:`InputIgnored`)."""

    NOT_STARTED = "not_started"  # a command on the welcome screen (a number there starts)
    FINISHED = "finished"  # the session is over
    NO_OPEN_ATTEMPT = "no_open_attempt"  # between questions, closing, explanation
    ALREADY_ANSWERED = "already_answered"  # another answer already won this attempt
    NO_SUCH_OPTION = "no_such_option"  # e.g. button 4 on a question with 3 options
    PAUSED = "paused"
    DOCTOR_CALLED = "doctor_called"  # halted until a clinician continues
    VOICE_OFF = "voice_off"  # live adaptation stopped listening for speech
    NOT_PAUSED = "not_paused"  # resume without a pause
    ALREADY_CALLED = "already_called"  # call-doctor while already waiting for the doctor
    NOT_HALTED = "not_halted"  # clinician continue with no doctor called
    PERSON_ALREADY_LOST = "person_already_lost"
    PERSON_NOT_LOST = "person_not_lost"
    UNKNOWN_LANGUAGE = "unknown_language"
    NOTHING_TO_UNDO = "nothing_to_undo"  # no answer can be taken back now
    UNSURE_REPLY = "unsure_reply"  # an unsure "yes" never confirms an unsure answer
    WAITING_FOR_TOUCH = "waiting_for_touch"  # unattended: only a touch or a press goes on, not a voice
    CALL_ASKED = "call_asked"  # "Shall I call the nurse?" waits for Yes or No
    NOT_AN_INPUT_CHANNEL = "not_an_input_channel"  # the camera sees; it gives no answers or commands


#: attempts per question: the question is asked, then asked again, then it is not answered. Fixed
#: by the CLARC model, whose contexts are FirstAttemptAnswered and SecondAttemptAnswered.
ATTEMPTS = 2


# Events published to listeners. ``t`` is seconds since the session was created (the QoS time).


@record
class SessionEvent:
    """Base of everything a session publishes."""

    t: float


@record
class PhaseChanged(SessionEvent):
    """The session moved to another phase (the UI shows another screen)."""

    phase: Phase
    previous: Phase


@record
class LanguageChanged(SessionEvent):
    """The patient chose another language; prompts from now on use it."""

    language: str


@record
class PromptOption:
    """An answer option as a prompt presents it: the voice grammar is built from these."""

    number: int
    label: str
    #: extra words the patient may say for this option, in the prompt's language
    synonyms: tuple[str, ...]
    #: points scored (None for practice questions)
    points: int | None


@record
class Prompt(SessionEvent):
    """Something to show and say now: a question, a practice question or a message.

    ``kind`` is "question", "practice", "confirm" (is the answer heard right? options Yes and No),
    "welcome" (options: start in each language) or "message"; ``key`` is the item id, the practice
    question id or the message name ("welcome", "explanation", "paused", "voice_off", ...). The
    voice channel listens for a prompt's options while the session is listening.
    """

    kind: str
    key: str
    text: str
    spoken: str
    language: str
    options: tuple[PromptOption, ...] = ()
    #: the question is being asked again (attempt 2, or the patient asked to repeat)
    repeat: bool = False
    attempt: int | None = None
    #: speech rate factor for the voice out (1.0 normal; live adaptation may slow it down)
    speech_rate: float = 1.0


@record
class AttemptOpened(SessionEvent):
    """An attempt at a question is open for answers until ``deadline`` (session time)."""

    item_id: str
    #: 1-based position of the question (for "Question 3 of 10"); 0-based never leaks out
    number: int
    attempt: int
    deadline: float
    practice: bool = False


@record
class AnswerRecorded(SessionEvent):
    """An answer was accepted (and, with a store, committed) for a scored item."""

    item_id: str
    number: int
    option: int
    points: int
    attempt: int
    channel: Channel
    answered_by: AnsweredBy
    detail: str = ""


@record
class PracticeAnswered(SessionEvent):
    """A familiarisation question got an answer (``option`` None: it got none)."""

    question_id: str
    option: int | None
    correct: bool
    channel: Channel | None


@record
class PracticeSkipped(SessionEvent):
    """A familiarisation question was not asked, e.g. a hearing check while voice out is off."""

    question_id: str
    #: what it would have checked: "hear", "read" or "select"
    checks: str
    reason: str


@record
class AttemptTimedOut(SessionEvent):
    """An attempt's window ended without an answer."""

    item_id: str
    number: int
    attempt: int
    practice: bool = False


@record
class QuestionNotAnswered(SessionEvent):
    """Both attempts timed out; the session goes on to the next question."""

    item_id: str
    number: int


@record
class Paused(SessionEvent):
    """The patient paused the session; the attempt clock is frozen."""

    channel: Channel | None


@record
class Resumed(SessionEvent):
    """The session goes on after a pause; ``deadline`` is the open attempt's new deadline, if any."""

    deadline: float | None


@record
class DoctorCalled(SessionEvent):
    """The patient called the doctor; the session is halted until a clinician continues it."""

    channel: Channel | None


@record
class DoctorContinued(SessionEvent):
    """A clinician continued a halted session."""

    deadline: float | None


@record
class PersonLost(SessionEvent):
    """The patient is no longer in front of the kiosk; the attempt clock is frozen."""

    #: who said so (None: an older caller that did not say)
    source: PresenceSource | None = None


@record
class PersonBack(SessionEvent):
    """The patient is back; ``deadline`` is the open attempt's new deadline, if any."""

    deadline: float | None
    source: PresenceSource | None = None


@record
class AwayAlert(SessionEvent):
    """The patient has been away for ``away_s`` (the site's ``away_alert_after_s``): the ward is
    alerted (logged ``away_alert``, an alert row for the station)."""

    away_s: float


@record
class Unattended(SessionEvent):
    """``count`` questions in a row were not answered (the site's ``unattended_after``): the ward is
    alerted and the kiosk waits for a touch before the next question."""

    count: int


@record
class UnattendedEnded(SessionEvent):
    """Someone touched the screen (or pressed a key or the remote) while the kiosk waited: the test
    goes on with the next question."""

    channel: Channel


@record
class InputIgnored(SessionEvent):
    """An input changed nothing; logged so a clinician can see what happened."""

    input: ChannelInput | None
    reason: IgnoreReason
    #: what was attempted when ``input`` is None (e.g. "resume", "clinician_continue")
    action: str = ""


@record
class ListeningChanged(SessionEvent):
    """Whether the voice channel should listen for answers now."""

    listening: bool


@record
class VolumeChanged(SessionEvent):
    """The patient asked for louder (+1) or quieter (-1) speech."""

    step: int


@record
class AdaptationChanged(SessionEvent):
    """Live adaptation switched something on or off (e.g. "voice_off", "slow_speech")."""

    name: str
    active: bool
    reason: str


@record
class MetricsUpdated(SessionEvent):
    """The QoS engine took a batch of contexts, or ran one on its own as time passed (the model's
    timers and time windows: ``set`` and ``emit`` empty); its metrics and fired observations after it."""

    metrics: Mapping[str, float]
    fired: tuple[str, ...]
    set: Mapping[str, Any]
    emit: tuple[str, ...]
    #: the model's timers that fired in this batch
    timers: tuple[str, ...] = ()


@record
class ConfirmationAsked(SessionEvent):
    """An answer the channel was not sure of is not stored yet: the patient is asked "I heard:
    <option>. Is that right?" (the prompt that follows has the Yes/No options)."""

    item_id: str
    number: int
    #: the option heard, and the channel it came through
    option: int
    attempt: int
    channel: Channel
    #: session time the confirmation times out (the answer is then not stored)
    deadline: float


@record
class AnswerNotConfirmed(SessionEvent):
    """An answer waiting for confirmation was not stored: ``why`` is "declined" (No), "undone"
    (the undo command) or "timed_out" (no reply: the attempt ends unanswered)."""

    item_id: str
    number: int
    option: int
    attempt: int
    why: str


@record
class AnswerWithdrawn(SessionEvent):
    """A stored answer was taken back ("Change my answer") and its question is asked again until
    ``deadline``; ``by`` is the channel the undo came through."""

    item_id: str
    number: int
    option: int
    points: int
    attempt: int
    channel: Channel
    by: Channel | None
    deadline: float


@record
class DoctorCallAsked(SessionEvent):
    """A call for the doctor was heard by voice and is not made yet: "Shall I call the nurse?"
    waits for Yes or No until ``deadline`` (None while the clock is stopped). Yes, a second
    hearing of the call or the doctor's key makes it (:class:`DoctorCalled`)."""

    detail: str
    confidence: float | None
    deadline: float | None


@record
class DoctorCallNotConfirmed(SessionEvent):
    """The call heard by voice was not made: the patient said or pressed No (``why``
    "declined", ``channel`` the one that said it) or nobody replied in time ("unanswered")."""

    why: str
    channel: Channel | None


@record
class DoctorCallCancelled(SessionEvent):
    """The patient said "I'm fine, carry on" after calling the doctor; the test goes on."""

    channel: Channel | None
    deadline: float | None


@record
class NextPatient(SessionEvent):
    """The end screen has been shown long enough: the kiosk goes back to the welcome for the next
    patient (the finished session's result stays stored for staff)."""


@record
class Finished(SessionEvent):
    """The questionnaire is over; the score is recomputed from the recorded answers."""

    score: Score
