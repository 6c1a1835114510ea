"""The Barthel session state machine: pure Python, injected clock, no Textual.

One :class:`Session` administers one questionnaire to one patient. It runs identically under the
Textual UI, in scripted replays (``kiosk replay``) and in tests, because everything it needs comes
in from outside:

* time from a :class:`~kiosk.core.clock.Clock`; nothing happens on its own -- a driver calls
  :meth:`Session.poll` at (or after) :meth:`Session.next_deadline` to let time-outs happen;
* patient input as :class:`~kiosk.core.channels.ChannelInput` and presence reports as
  :class:`~kiosk.core.channels.Presence` (camera or staff) through :meth:`Session.handle`, and the
  other inputs (start, clinician) as methods;
* the QoS engine (``qos.Engine``) it tells about contexts, exactly as the CLARC context table says;
* an optional store (``kiosk.store.database.Store``) that commits every answer as it happens.

Everything the session does is published to listeners (:meth:`Session.subscribe`) as small frozen
dataclass events (:class:`Prompt`, :class:`AttemptOpened`, :class:`AnswerRecorded`, ...), after the
operation that caused them has finished, in order.

Flow: WELCOME --start()--> FAMILIARISATION (practice questions, optional) --> EXPLANATION
--acknowledge()--> QUESTIONS --> SUMMARY. A battery's later instrument (:mod:`.battery`) starts
in REST ("Well done. Next: <title>.") --acknowledge()--> EXPLANATION, with no practice questions.
Each question: attempt 1 (prompt; wait
``attempt_window_s``) -> attempt 2 (prompt repeated; wait) -> not answered, next question.

Timing rules (all values from :class:`~kiosk.core.questionnaire.Timing`):

* The first answer of an attempt wins; a later one for the same attempt is ignored (and published
  as :class:`InputIgnored`).
* An input at time t is handled before a time-out due at t: an attempt's window includes its end.
* Pause freezes the attempt clock; on resume at least ``resume_grace_s`` is left. Call-doctor halts
  the session (answers are ignored) until :meth:`Session.clinician_continue`; then at least
  ``resume_grace_s`` is left. Person lost freezes the clock; person back leaves at least
  ``person_back_grace_s``. The gap between questions and the closing delay freeze likewise.
* After an answer or an unanswered question the next attempt 1 opens ``between_questions_s``
  later; after the last question FINISHED comes ``closing_s`` later.
* While a gap runs, :attr:`Snapshot.interlude` names what to show meanwhile ("next question...").
* Practice questions that check hearing are skipped while voice out is unavailable
  (:meth:`Session.set_voice_out_available`); practice outcomes are stored for the clinician.
* An answer while the patient is reported lost is still taken (a touch proves someone is there);
  PersonDetected stays the presence source's business, and the next question waits for it.
* Away for the site's ``away_alert_after_s`` (:class:`Watching`), the ward is alerted
  (``away_alert``); after ``unattended_after`` unanswered questions in a row the ward is alerted
  (``unattended``) and the kiosk waits for a touch instead of asking on (:mod:`.attendance`).

QoS contexts (one batch per instant; practice answers are never published):
start -> ``PersonDetected: true, TestState: STARTED``; answer on attempt 1 ->
``FirstAttemptAnswered: true, UserInteraction: <channel>``; attempt 1 timed out ->
``FirstAttemptAnswered: false``; attempt 2 likewise with ``SecondAttemptAnswered``; pause ->
``TestState: PAUSED``; resume and clinician continue -> ``TestState: RESTARTED``; call doctor ->
``emit: [CallingDoctor]``; repeat -> ``TestState: REPEATING`` (back to ``STARTED`` with the next
batch, or when :meth:`Session.prompt_delivered` says the repeated prompt was spoken); person
lost/back -> ``PersonDetected: false/true``; finish -> ``TestState: FINISHED``.
The keyboard maps to ``TOUCH_SCREEN``: the on-screen number keys are on the same kiosk panel as
the touchscreen, and the CLARC model has no keyboard literal.

The package, one concept a module, each a plain class given what it needs in its constructor
(none imports :class:`Session`): :mod:`.events` (what is published), :mod:`.snapshot` (what a
screen renders), :mod:`.state` (the one shared state), :mod:`.timers` (the attempt clock),
:mod:`.publishing` (QoS batches, log, listeners, the operation bracket), :mod:`.prompts` (what is
shown and said), :mod:`.opening` (welcome, start, language, explanation), :mod:`.questions`
(attempts, answers, time-outs, finish), :mod:`.corrections` (confirm an unsure answer, undo the
last one), :mod:`.practice` (familiarisation), :mod:`.incidents` (pause, call-doctor), :mod:`.attendance`
(presence, the away alert, the wait for a touch), :mod:`.calls` (a call heard by voice asked back:
"Shall I call the nurse?"),
:mod:`.live` (live adaptation), :mod:`.routing` (which step takes an input or a time-out),
:mod:`.resume` (continuing a stored session), :mod:`.ports` (what it needs of the engine and the
store) and :mod:`.core` (the :class:`Session` that owns them).
"""

from kiosk.core.session.attendance import Watching
from kiosk.core.session.core import Session
from kiosk.core.session.events import (
    ATTEMPTS,
    AdaptationChanged,
    AnsweredBy,
    AnswerNotConfirmed,
    AnswerRecorded,
    AnswerWithdrawn,
    AttemptOpened,
    AttemptTimedOut,
    AwayAlert,
    ConfirmationAsked,
    DoctorCallAsked,
    DoctorCallCancelled,
    DoctorCalled,
    DoctorCallNotConfirmed,
    DoctorContinued,
    Finished,
    IgnoreReason,
    InputIgnored,
    LanguageChanged,
    ListeningChanged,
    MetricsUpdated,
    NextPatient,
    Paused,
    PersonBack,
    PersonLost,
    Phase,
    PhaseChanged,
    PracticeAnswered,
    PracticeSkipped,
    Prompt,
    PromptOption,
    QuestionNotAnswered,
    Resumed,
    SessionEvent,
    Unattended,
    UnattendedEnded,
    VolumeChanged,
)
from kiosk.core.session.ports import QosEngine, SessionStore
from kiosk.core.session.publishing import SAME_INSTANT_STEP_S, USER_INTERACTION, Listener
from kiosk.core.session.snapshot import Answer, Snapshot

__all__ = [
    "ATTEMPTS",
    "SAME_INSTANT_STEP_S",
    "USER_INTERACTION",
    "AdaptationChanged",
    "Answer",
    "AnsweredBy",
    "AnswerNotConfirmed",
    "AnswerRecorded",
    "AnswerWithdrawn",
    "AttemptOpened",
    "AttemptTimedOut",
    "AwayAlert",
    "ConfirmationAsked",
    "DoctorCallAsked",
    "DoctorCallCancelled",
    "DoctorCalled",
    "DoctorCallNotConfirmed",
    "DoctorContinued",
    "Finished",
    "IgnoreReason",
    "InputIgnored",
    "LanguageChanged",
    "Listener",
    "ListeningChanged",
    "MetricsUpdated",
    "NextPatient",
    "Paused",
    "PersonBack",
    "PersonLost",
    "Phase",
    "PhaseChanged",
    "PracticeAnswered",
    "PracticeSkipped",
    "Prompt",
    "PromptOption",
    "QosEngine",
    "QuestionNotAnswered",
    "Resumed",
    "Session",
    "SessionEvent",
    "SessionStore",
    "Snapshot",
    "Unattended",
    "UnattendedEnded",
    "VolumeChanged",
    "Watching",
]
