"""The kiosk's Textual app: wires the session, the channels and the QoS engine to the screens.

Nothing is decided here. The app

* forwards every input -- a touch, a key, a remote press or a voice answer -- to the
  :class:`~kiosk.core.session.Session` as a :class:`~kiosk.core.channels.ChannelInput`;
* calls :meth:`Session.poll` from a timer, so the session's own time-outs happen (the session
  reads time from its injected clock; tests use a :class:`~kiosk.core.clock.SimClock`);
* reacts to the session's events: speaks prompts, tells the recogniser when to listen, and
  switches to the screen the session's :meth:`~kiosk.core.session.Session.snapshot` calls for.

Channels run on their own threads and only ever call :meth:`KioskApp.channel_sink`, which posts a
small message to the UI thread; no thread touches a widget. A channel that is missing (no
microphone, no espeak-ng, no remote) is shown as off with its reason and the session goes on.

`kiosk run` (also plain `kiosk`) is :func:`main`.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sqlite3
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

from textual import events
from textual.app import App
from textual.binding import Binding
from textual.message import Message

from kiosk.core.channels import Channel, ChannelInput, ChannelState, ChannelStatus, Command, InputSource
from kiosk.core.pin import CornerTaps, PinGuard
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.session import (
    AnswerRecorded,
    DoctorCalled,
    IgnoreReason,
    InputIgnored,
    ListeningChanged,
    NextPatient,
    Paused,
    Phase,
    Prompt,
    Session,
    SessionEvent,
    VolumeChanged,
)
from kiosk.export import ExportSite, export_identity, site_from_config
from kiosk.export.captured import questionnaire_of
from kiosk.export.opening import in_force_of
from kiosk.remote.buttons import KIOSK_KEY_BUTTONS
from kiosk.store.database import Store, StoredSession
from kiosk.store.lease import LEASE_TTL_S, SessionTaken
from kiosk.ui.screens.base import ClinicianScreen, PatientScreen, PatientView, Ways, spoken_with_ways
from kiosk.ui.screens.clinician_home import ClinicianHomeScreen
from kiosk.ui.screens.doctor_called import DoctorCalledScreen
from kiosk.ui.screens.explanation import ExplanationScreen
from kiosk.ui.screens.familiarisation import FamiliarisationScreen
from kiosk.ui.screens.out_of_order import OutOfOrderScreen
from kiosk.ui.screens.paused import PausedScreen
from kiosk.ui.screens.pin import PinScreen
from kiosk.ui.screens.question import QuestionScreen
from kiosk.ui.screens.summary import SummaryScreen
from kiosk.ui.screens.visit_ready import VisitReadyScreen
from kiosk.ui.screens.welcome import WelcomeScreen
from kiosk.ui.widgets.answer_button import AnswerButton
from kiosk.ui.widgets.bars import ControlBar, VoiceAgainButton
from kiosk.ui.widgets.change_answer import ChangeAnswerButton
from kiosk.ui.widgets.channel_board import REMOTE, VOICE_IN, VOICE_OUT, ChannelBoard
from kiosk.ui.widgets.waiting_sign import WaitingSign

#: the kiosk display's size in cells (columns, rows): snapshots and the bench use it
KIOSK_SIZE = (100, 32)
#: the clinician screens open with this chord, then ask for the PIN
CLINICIAN_CHORD = "ctrl+k"
#: how often the session is polled for time-outs (seconds); it fires them at their own due time
POLL_INTERVAL = 0.1
#: the source name the voice-out statuses carry when no speaker is wired
VOICE_OUT_SOURCE = "espeak-ng"
#: seconds the PIN pad waits for a touch or key before it goes back to the patient (a patient who
#: tapped the corner five times is not left on it)
PIN_IDLE_S = 60.0
#: the same for the clinician screens behind the PIN (staff walked away: the patient's screen returns)
CLINICIAN_IDLE_S = 300.0
#: bytes the kiosk must be able to write beside its database before an out-of-order kiosk takes
#: patients again (a test's rows, its QoS trace and the WAL need room to grow)
PROBE_BYTES = 256 * 1024


@dataclass
class ChannelReceived(Message):
    """A channel thread delivered an input or a status change (posted, never handled on that thread)."""

    item: ChannelInput | ChannelStatus


@dataclass
class SpeechActivity(Message):
    """Voice out started (True) or stopped (False) talking."""

    speaking: bool


class KioskApp(App[int], inherit_bindings=False):
    """The patient's kiosk, with the clinician screens behind a PIN pad.

    Locked down: nothing a patient can press leaves or reconfigures it. Textual's own keys are
    not inherited (ctrl+q quit, ctrl+c) and there is no command palette (ctrl+p: quit, theme,
    screenshot). Staff open the PIN pad with five taps on the top-left corner (or ``ctrl+k``);
    quitting is a button behind the PIN.

    ``session`` is a fresh (not yet started) session. ``speaker`` is a ``kiosk.speech.tts.Speaker``
    or None (voice out off); ``voice`` a ``kiosk.speech.voice.VoiceChannel`` (an input source that
    also follows the session's events) or None; ``sources`` the remotes' input sources
    (all started with :meth:`channel_sink` on mount and stopped on exit). ``statuses`` are channel
    states known before start-up, such as "voice in off: no microphone found". ``keyboard`` is a
    ``kiosk.remote.KeyboardRemote`` for remotes that type keys. ``resume`` builds the session
    continuing an interrupted stored one (``Session.from_stored``): staff choose it on the clinician
    screen ("Continue this test"); a patient is never offered someone else's test. ``new_session``
    builds a fresh session for the next patient (the clinician's "New session").

    With a store, the app renews this kiosk's hold on its session every ``lease_interval`` seconds
    and marks interrupted the tests whose kiosk is gone (:meth:`Store.interrupt_stale`); a session
    this kiosk no longer holds (taken over, or too old) is dropped with a plain notice.
    """

    CSS_PATH = "kiosk.tcss"
    TITLE = "Barthel kiosk"
    #: no text selection: taps (the five on the staff corner) must not leave a highlighted word
    ALLOW_SELECT = False
    BINDINGS = [Binding(CLINICIAN_CHORD, "clinician", "Clinician", show=False, priority=True)]
    ENABLE_COMMAND_PALETTE = False

    def __init__(
        self,
        session: Session,
        *,
        clinician_pin: str | PinGuard,
        store: Store | None = None,
        speaker: Any = None,
        voice: Any = None,
        sources: Iterable[InputSource] = (),
        keyboard: Any = None,
        statuses: Iterable[ChannelStatus] = (),
        export_dir: Path | None = None,
        export_site: ExportSite | None = None,
        poll_interval: float = POLL_INTERVAL,
        resume: Callable[[StoredSession], Session] | None = None,
        new_session: Callable[[], Session] | None = None,
        show_score: bool = False,
        sync: Any = None,
        visits: Any = None,
        orders: Any = None,
        start_order: Callable[[str], Any] | None = None,
    ) -> None:
        super().__init__()
        # the clinician's widgets (tables, switches, the plot) follow the theme: light like the rest
        self.theme = "textual-light"
        self.session = session
        self.questionnaire: Questionnaire = session.questionnaire
        self.store = store
        #: checks the clinician PIN (a plain string: an in-memory guard, for tests and benches)
        self.pin_guard = clinician_pin if isinstance(clinician_pin, PinGuard) else PinGuard(clinician_pin)
        self._corner = CornerTaps()
        self.speaker = speaker
        self.voice = voice
        self.sources = list(sources)
        self.keyboard = keyboard
        self.export_dir = export_dir
        #: the site and kiosk the clinician's exports name (the same identifiers as `kiosk results`)
        self.export_site = export_site or ExportSite()
        self.poll_interval = poll_interval
        self._resume = resume
        self._new_session = new_session
        #: the end screen shows the patient their total and band (config show_score_to_patient)
        self.show_score = show_score
        #: the ward station's client (``kiosk.sync.SyncClient``), or None: no station, no threads
        self.sync = sync
        #: how visits begin (``kiosk.core.visits.VisitDesk``; None: every welcome is a walk-up, as before);
        #: ``orders`` the station's order watcher, ``start_order(code)`` the call that starts one
        self.visits = visits
        self.orders = orders
        self._start_order = start_order
        self.board = ChannelBoard(getattr(speaker, "source", VOICE_OUT_SOURCE))
        if speaker is not None:  # its worker thread reports through these (it starts on mount)
            speaker.on_status, speaker.on_speech = self.speaker_status, self.speaker_activity
        else:
            self.board.update(ChannelStatus(Channel.VOICE, ChannelState.OFF, VOICE_OUT_SOURCE, "voice out turned off"))
        for status in statuses:
            self.board.update(status)
        #: every session event the app received, in order (the clinician screens and tests read it)
        self.events: list[SessionEvent] = []
        self._screen_key: tuple[type, object] | None = None
        self._dirty = False
        #: a repeated prompt on its way through the speaker: "queued", then "speaking"
        self._repeat: str | None = None
        #: the session the clinician screens paused on opening (they resume it on leaving)
        self._held: Session | None = None
        #: the patient pressed a number the question on screen does not have (a hint shows)
        self._no_such_option = False
        #: session time of the last touch or key on a staff screen (their idle time-out counts from it)
        self._staff_seen = 0.0
        #: why the kiosk takes no patient now (the store failed), for staff; None while it works
        self.out_of_order: str | None = None
        self._unsubscribe = self.session.subscribe(self._on_session_event)
        self._tell_voice_available()

    # -- start and stop -------------------------------------------------------------------------

    def on_mount(self) -> None:
        """Start the channels and the poll timer, and show the welcome screen."""
        if self.speaker is not None:
            self.speaker.start()
        for source in self._input_sources():
            # loading a speech model or probing a device can take a while: never on the UI thread
            self.run_worker(
                partial(source.start, self.channel_sink), thread=True, name=f"start {source.name}", group="channels"
            )
        self.set_interval(self.poll_interval, self.poll_session)
        if self.store is not None:
            self.set_interval(LEASE_TTL_S / 3, self.keep_session)
        self._greet()
        if self.sync is not None:
            self.sync.start()
        if self.orders is not None:
            self.orders.start()
        self._render()

    def on_unmount(self) -> None:
        """Stop every channel (each stop is safe to call twice) and the station's client."""
        if self.sync is not None:
            self.sync.stop()
        if self.orders is not None:
            self.orders.stop()
        for source in self._input_sources():
            source.stop()
        if self.speaker is not None:
            self.speaker.close()

    def _input_sources(self) -> list[InputSource]:
        return self.sources + ([self.voice] if self.voice is not None else [])

    # -- from the channels' threads ---------------------------------------------------------------

    def channel_sink(self, item: ChannelInput | ChannelStatus) -> None:
        """The sink every channel delivers to, from its own thread: posts to the UI thread."""
        self.post_message(ChannelReceived(item))

    def speaker_status(self, status: ChannelStatus) -> None:
        """The speaker's status callback (worker thread)."""
        self.post_message(ChannelReceived(status))

    def speaker_activity(self, speaking: bool) -> None:
        """The speaker's speech start/end callback (worker thread). The recogniser is muted right
        here, not after the hop to the UI thread, so none of the kiosk's own voice reaches it."""
        if self.voice is not None:
            self.voice.set_muted(speaking)
        self.post_message(SpeechActivity(speaking))

    def on_channel_received(self, message: ChannelReceived) -> None:
        """An input goes to the session; a status change to the channel bar."""
        if isinstance(message.item, ChannelStatus):
            self.board.update(message.item)
            if self.board.indicator(message.item) in (VOICE_IN, VOICE_OUT):
                self._drive(self._tell_voice_available)
            self._render()
        else:
            self.forward(message.item)

    def on_speech_activity(self, message: SpeechActivity) -> None:
        """Show "speaking", and tell the session once a repeated prompt has been said (the speaker
        works through its phrases in order, so the repeat is the phrase that starts after it was
        queued; a phrase cut short for it ends before)."""
        self.board.speaking = message.speaking
        if message.speaking and self._repeat == "queued":
            self._repeat = "speaking"
        elif not message.speaking and self._repeat == "speaking":
            self._repeat = None
            self._drive(self.session.prompt_delivered)
            return
        self._render()

    # -- from the screens (UI thread) -------------------------------------------------------------

    def patient_key(self, key: str) -> bool:
        """A key pressed on a patient screen; True if it meant something to the kiosk."""
        item = self.keyboard.translate(key) if self.keyboard is not None else None
        if item is None and key not in KIOSK_KEY_BUTTONS:  # "C" (or "shift+c") is C
            key = key.removeprefix("shift+").lower() if len(key.removeprefix("shift+")) == 1 else key
        if item is None and key in KIOSK_KEY_BUTTONS:
            meaning = KIOSK_KEY_BUTTONS[key]
            detail = f"key {key}"
            item = (
                ChannelInput(Channel.KEYBOARD, command=meaning, detail=detail)
                if isinstance(meaning, Command)
                else ChannelInput(Channel.KEYBOARD, option=meaning, detail=detail)
            )
        if item is None:
            return False
        self.forward(item)
        return True

    def on_answer_button_chosen(self, message: AnswerButton.Chosen) -> None:
        """A touched answer is a touch input."""
        self.forward(ChannelInput(Channel.TOUCH, option=message.option, detail="screen"))

    def on_control_bar_commanded(self, message: ControlBar.Commanded) -> None:
        """A touched Pause/Continue/Repeat/Call-doctor is a touch command."""
        self.forward(ChannelInput(Channel.TOUCH, command=message.command, detail="screen"))

    def on_voice_again_button_requested(self, message: VoiceAgainButton.Requested) -> None:
        """The patient asked to answer by voice again; the session decides."""
        self._drive(self.session.request_voice)

    def on_welcome_screen_language_chosen(self, message: WelcomeScreen.LanguageChosen) -> None:
        """Start in the language the patient touched."""
        if not self._welcome_held():
            self._start(message.language)

    def _replace_session(self, session: Session) -> None:
        old, self.session = self.session, session
        self._unsubscribe()
        if self.store is not None and old.id != session.id:
            with contextlib.suppress(sqlite3.Error):  # else keep_session lets it go later
                self.store.release(old.id)  # a finished one is let go; one still running is interrupted
        self._unsubscribe = self.session.subscribe(self._on_session_event)
        self._tell_voice_available()
        if self.visits is not None:
            self.visits.next_visit()

    def _greet(self) -> None:
        """A fresh session's welcome is said, and listened to: "start", or a language's name
        (not while the welcome waits for staff to confirm an ordered visit)."""
        if self.session.phase is Phase.WELCOME and not self._welcome_held():
            self._drive(self.session.welcome)

    def on_change_answer_button_requested(self, message: ChangeAnswerButton.Requested) -> None:
        """ "Change my answer" is the undo command, by touch; the session decides if it still can."""
        self.forward(ChannelInput(Channel.TOUCH, command=Command.UNDO, detail="screen"))

    def on_doctor_called_screen_carry_on(self, message: DoctorCalledScreen.CarryOn) -> None:
        """The patient touched "I'm fine, carry on" after calling the doctor."""
        self._drive(self.session.cancel_doctor_call, Channel.TOUCH)

    def on_explanation_screen_understood(self, message: ExplanationScreen.Understood) -> None:
        """The patient touched Start under the explanation."""
        self._drive(self.session.acknowledge)

    def forward(self, item: ChannelInput) -> None:
        """Hand an input to the session (what a number means on each screen is the session's call);
        nothing while the kiosk is out of order, and none starts a test while the welcome waits for
        staff (an ordered visit, no walk-ups)."""
        if self.out_of_order is not None:
            return
        if self.session.phase is Phase.WELCOME and self._welcome_held():
            return
        self._drive(self.session.handle, item)

    def _start(self, language: str) -> None:
        if self.out_of_order is not None:
            return

        def start() -> None:
            self.session.choose_language(language)
            self.session.start()

        self._drive(start)

    def poll_session(self) -> None:
        """Let the session's due time-outs happen (the poll timer calls this), and move the
        waiting sign's dot on with the session's clock. Nothing while no screen is up: the timer
        can still fire while the app is closing (as when another kiosk holds the test)."""
        if not self.screen_stack:
            return
        self._drive(self.session.poll)
        self._staff_idle()
        if isinstance(self.screen, PatientScreen):
            for sign in self.screen.query(WaitingSign):
                sign.tick(self.session.now())

    # -- the session's events ----------------------------------------------------------------------

    def _drive(self, operation: Callable[..., object], *args: object) -> None:
        """Run a session operation, then redraw if it published anything. A session another kiosk
        took over (or that was interrupted) stores nothing more here: the kiosk lets it go."""
        try:
            operation(*args)
        except SessionTaken as taken:
            self._session_lost(str(taken))
            return
        except sqlite3.Error as failed:  # the step was rolled back: the session in memory is ahead of it
            self._store_failed(failed)
            return
        if self._dirty:
            self._dirty = False
            self._render()
        self._report_status()

    def _on_session_event(self, event: SessionEvent) -> None:
        """Carry out what an event asks of the channels; the redraw follows the operation."""
        self.events.append(event)
        self._dirty = True
        if self.voice is not None:  # its grammar follows the prompts, its gate the listening state
            self.voice.on_session_event(event)
        if isinstance(event, Prompt):
            self._speak(event)
        elif isinstance(event, ListeningChanged):
            self.board.listening = event.listening
        elif isinstance(event, InputIgnored):
            self._no_such_option = event.reason is IgnoreReason.NO_SUCH_OPTION
        if isinstance(event, (Prompt, AnswerRecorded)):  # the hint was about the question before
            self._no_such_option = False
        if isinstance(event, (AnswerRecorded, Paused, DoctorCalled)):
            if self.speaker is not None:
                self.speaker.stop_speaking()
        elif isinstance(event, VolumeChanged) and self.speaker is not None:
            (self.speaker.volume_up if event.step > 0 else self.speaker.volume_down)()
        elif isinstance(event, NextPatient):
            self.call_later(self._next_patient)

    def _next_patient(self) -> None:
        """The end screen was shown long enough: the welcome, with a fresh session, for the next
        patient (the finished result stays in the store for staff)."""
        if self._new_session is None or not self.session.finished:
            return
        self._replace_session(self._new_session())
        self._screen_key = None
        self._greet()
        self._render()

    def _speak(self, prompt: Prompt) -> None:
        if self.speaker is None or not prompt.spoken:
            return
        from kiosk.speech.tts import DEFAULT_RATE

        if prompt.repeat:  # asked again: what was still queued is superseded
            self.speaker.stop_speaking()
            self._repeat = "queued"
        self.speaker.rate = round(DEFAULT_RATE * prompt.speech_rate)
        self.speaker.say(spoken_with_ways(prompt.spoken, prompt.language, self._view().ways), prompt.language)

    def _tell_voice_available(self) -> None:
        """Tell the session whether voice in and voice out are on (it decides what that means for
        adaptation and for the practice questions)."""
        self.session.set_voice_available(self.board.state(VOICE_IN)[0] is ChannelState.ON)
        self.session.set_voice_out_available(self.board.state(VOICE_OUT)[0] is ChannelState.ON)

    # -- drawing -------------------------------------------------------------------------------

    def _view(self) -> PatientView:
        snap = self.session.snapshot()
        voice_in = self.board.state(VOICE_IN)[0] is ChannelState.ON
        # the session lifts voice_off when voice in goes; checked here too so the button never
        # promises listening that cannot happen (and not over Continue while paused)
        voice_again = "voice_off" in snap.adaptations and not (snap.paused or snap.halted) and voice_in
        ways = Ways(
            remote=self.board.state(REMOTE)[0] is ChannelState.ON,
            voice=voice_in and "voice_off" not in snap.adaptations,
            listening=voice_in and self.board.listening,
            voice_out=self.board.state(VOICE_OUT)[0] is ChannelState.ON,
        )
        question = snap.item or snap.practice
        hint = len(question.options) if self._no_such_option and question is not None else None
        return PatientView(
            snap,
            self.questionnaire,
            ways,
            voice_again=voice_again,
            hint_options=hint,
            now=self.session.now(),
            show_score=self.show_score,
        )

    @staticmethod
    def _screen_classes(view: PatientView) -> tuple[type[PatientScreen], type[PatientScreen] | None]:
        """The screen of the session's phase, and the one covering it while paused or halted."""
        snap = view.snapshot
        base = {
            Phase.WELCOME: WelcomeScreen,
            Phase.FAMILIARISATION: FamiliarisationScreen,
            Phase.EXPLANATION: ExplanationScreen,
            Phase.QUESTIONS: QuestionScreen,
            Phase.SUMMARY: SummaryScreen,
        }[snap.phase]
        overlay = DoctorCalledScreen if snap.halted else PausedScreen if snap.paused else None
        return base, overlay

    def _render(self) -> None:
        """Show the screens the session's state calls for, or refresh the ones shown.

        The phase's screen stays mounted under a paused or doctor-called screen, so resuming
        only uncovers it; it is rebuilt only when its :meth:`PatientScreen.key` changes.
        """
        if not self.is_running or self.clinician_open:
            return
        view = self._view()
        base_cls, overlay_cls = self._screen_classes(view)
        if self.out_of_order is not None:
            base_cls, overlay_cls = OutOfOrderScreen, None
        shown = [s for s in self.screen_stack if isinstance(s, PatientScreen)]
        base, overlay = (shown + [None, None])[:2]
        key = (base_cls, base_cls.key(view))
        if base_cls is WelcomeScreen and self._welcome_held():  # kiosk.core.visits: staff confirm first
            base_cls, key = VisitReadyScreen, (VisitReadyScreen, self.visits.ready)
        if overlay is not None and (type(overlay) is not overlay_cls or key != self._screen_key):
            self.pop_screen()
            overlay = None
        if base is None:
            self.push_screen(self._make_screen(base_cls, view))
        elif key != self._screen_key:
            self.switch_screen(self._make_screen(base_cls, view))
        else:
            base.show(view)
        self._screen_key = key
        if overlay is not None:
            overlay.show(view)
        elif overlay_cls is not None:
            self.push_screen(overlay_cls(view))

    def _make_screen(self, base_cls: type[PatientScreen], view: PatientView) -> PatientScreen:
        if base_cls is VisitReadyScreen:
            return VisitReadyScreen(view, self.visits.ready, self.visits.walk_up)
        return base_cls(view)

    # -- visits: ordered, started by staff, walk-up (kiosk.core.visits) -------------------------------

    def _welcome_held(self) -> bool:
        return self.visits is not None and self.visits.holds_welcome()

    def orders_changed(self, orders: Any, problems: Any = ()) -> None:
        """The station's list of visits for this kiosk (UI thread): the welcome follows it."""
        if self.visits is not None and self.visits.set_orders(orders, problems) and self.session.phase is Phase.WELCOME:
            self._render()

    def on_visit_ready_screen_code_entered(self, message: VisitReadyScreen.CodeEntered) -> None:
        """Staff typed a visit's code: the station says which visit it starts (off the UI thread)."""
        if self._start_order is None:
            return
        starter = self._start_order

        def ask() -> None:
            try:
                order = starter(message.code)
            except Exception as refused:  # noqa: BLE001 - OrderRefused or Unreachable: said to staff
                self.call_from_thread(self._order_refused, str(refused) or type(refused).__name__)
                return
            self.call_from_thread(self._order_started, order)

        self.run_worker(ask, thread=True, name="start an order", group="orders")

    def _order_refused(self, why: str) -> None:
        if isinstance(self.screen, VisitReadyScreen):
            self.screen.refused(why if why.endswith(".") else f"The ward station cannot be reached ({why}).")

    def _order_started(self, order: Any) -> None:
        """The station started the visit: a session for its patient, in its language, begins."""
        if self.session.phase is not Phase.WELCOME:
            return
        self._replace_session(self.visits.for_order(order))
        self._drive(self.session.start, order.answered_by)

    def on_visit_ready_screen_walk_up_chosen(self, message: VisitReadyScreen.WalkUpChosen) -> None:
        if self.visits.choose_walk_up():
            self._greet()
            self._render()

    def start_staff_visit(self, patient_id: str, language: str, relative: bool) -> str | None:
        """Staff start a visit for the identifier they typed (clinician screen): why not, or None."""
        if self.visits is None:
            return "this kiosk cannot start visits for a patient identifier"
        if self.session.phase is not Phase.WELCOME and not self.session.finished:
            return "a test is in progress on this kiosk: finish it, or start a new patient, first"
        session, why = self.visits.for_staff(patient_id, language, relative)
        if session is None:
            return why
        self._replace_session(session)
        self.close_clinician()
        self._drive(self.session.start, session.answered_by)
        return None

    # -- the clinician side -------------------------------------------------------------------

    @property
    def clinician_open(self) -> bool:
        """A clinician screen (or the PIN prompt) is on top of the patient's screen."""
        return any(isinstance(s, ClinicianScreen) for s in self.screen_stack)

    def action_clinician(self) -> None:
        """The chord: ask for the PIN, then open the clinician screens."""
        if self.clinician_open:
            return

        def unlocked(ok: bool | None) -> None:
            if ok:
                self.push_screen(ClinicianHomeScreen())
            else:
                self._release_session()

        self._staff_seen = self.session.now()
        self.push_screen(PinScreen(self.pin_guard), unlocked)
        self._hold_session()

    def _staff_idle(self) -> None:
        """Back to the patient once the staff screens have had no touch or key for their idle time
        (the session's clock: a simulated one in tests and replays)."""
        if not self.clinician_open:
            return
        idle = PIN_IDLE_S if isinstance(self.screen, PinScreen) else CLINICIAN_IDLE_S
        if self.session.now() - self._staff_seen >= idle:
            self.close_clinician()

    async def on_event(self, event: events.Event) -> None:
        """Watch every press for the staff corner before the screens see it (a button under the
        corner must not hide the taps)."""
        if (
            isinstance(event, events.MouseDown)
            and not self.clinician_open
            and self._corner.tap(event.screen_x, event.screen_y)
        ):
            self.action_clinician()
        elif self.clinician_open and isinstance(
            event, (events.Key, events.MouseDown, events.MouseScrollDown, events.MouseScrollUp)
        ):
            self._staff_seen = self.session.now()
        await super().on_event(event)

    def quit_kiosk(self) -> None:
        """Staff end the kiosk (a button behind the PIN): it exits as after a normal close."""
        self.exit(0)

    def close_clinician(self) -> None:
        """Leave the clinician screens and show the patient's screen as the session now is."""
        while self.clinician_open:
            self.pop_screen()
        self._release_session()
        self._screen_key = None
        self.call_after_refresh(self._render)

    @property
    def held_for_clinician(self) -> bool:
        """The session is paused because the clinician screens are open (not by the patient)."""
        return self._held is self.session and self.session.paused

    def _hold_session(self) -> None:
        """Pause a running session while the clinician screens are open, so nothing times out
        unseen underneath (one already paused or halted stays as it is)."""
        session = self.session
        if session.phase in (Phase.FAMILIARISATION, Phase.EXPLANATION, Phase.QUESTIONS) and not (
            session.paused or session.halted
        ):
            self._drive(session.pause)
            self._held = session if session.paused else None

    def _release_session(self) -> None:
        """Resume the session the clinician screens paused (not one the patient paused)."""
        if self.held_for_clinician and not self.session.halted:
            self._drive(self.session.resume)
        self._held = None

    def clinician_continue(self) -> None:
        """A clinician continues a session halted by call-doctor (or paused)."""
        self._drive(self.session.clinician_continue)

    def person_lost(self) -> None:
        """A clinician says the patient left the kiosk (it has no presence sensor)."""
        self._drive(self.session.person_lost)

    def person_back(self) -> None:
        """A clinician says the patient is back in front of the kiosk."""
        self._drive(self.session.person_back)

    @property
    def can_start_new_session(self) -> bool:
        """A fresh session for the next patient can be built."""
        return self._new_session is not None

    def start_new_session(self) -> None:
        """The clinician starts over for the next patient; the session decides whether the one it
        replaces counts as abandoned (:meth:`Session.abandon`)."""
        if self._new_session is None:
            return
        try:
            self.session.abandon()
        except SessionTaken:
            pass  # another kiosk holds it now: nothing of it is this kiosk's to end
        self._replace_session(self._new_session())
        self._greet()
        self.close_clinician()

    # -- the ward station (kiosk.sync) ----------------------------------------------------------

    def _report_status(self) -> None:
        """Give the station's client what the ward view shows of this kiosk (sent when it changes)."""
        if self.sync is not None:
            from kiosk.sync.commands import live_status

            self.sync.set_status({**live_status(self.session), "out_of_order": self.out_of_order})

    def station_command(self, command: Any) -> tuple[str, str | None] | None:
        """A command from the ward station (called on the client's thread): applied on the UI thread."""
        from kiosk.sync.commands import apply_command

        return self.call_from_thread(apply_command, self, dict(command))

    def end_session(self, reason: str) -> None:
        """Staff end the running test (stored as abandoned, with why); the kiosk welcomes the next patient."""
        try:
            self.session.abandon(reason)
        except SessionTaken:
            pass  # another kiosk holds it now: nothing of it is this kiosk's to end
        if self._new_session is not None:
            self._replace_session(self._new_session())
            self._greet()
        self._screen_key = None
        self._render()
        self._report_status()

    # -- interrupted tests and this kiosk's hold on its session ------------------------------------

    def interrupted_tests(self) -> list[StoredSession]:
        """The tests staff may continue here (their kiosk stopped, or they grew too old), newest first."""
        return self.store.unfinished_sessions() if self.store is not None else []

    def continue_test(self, session_id: str) -> str | None:
        """Staff continue an interrupted test on this kiosk (clinician screen, behind the PIN).
        Returns why not, as a sentence for staff, or None once it continues."""
        if self.store is None or self._resume is None:
            return "this kiosk stores no sessions"
        if self.session.phase is not Phase.WELCOME and not self.session.finished:
            return "a test is in progress on this kiosk: finish it, or start a new patient, first"
        try:
            stored = self.store.continue_session(session_id)
        except (SessionTaken, ValueError, KeyError) as refused:
            return str(refused.args[0] if isinstance(refused, KeyError) else refused)
        self._replace_session(self._resume(stored))
        self.close_clinician()
        self._drive(self.session.start)
        return None

    def keep_session(self) -> None:
        """Renew this kiosk's hold on its session and interrupt the tests whose kiosk is gone (a
        timer calls this); a running session this kiosk no longer holds is let go."""
        assert self.store is not None
        session = self.session
        try:
            self.store.renew()
            self.store.release_others(session.id)  # one this kiosk dropped when it could not write
            self.store.interrupt_stale()
            why = None if session.phase is Phase.WELCOME or session.finished else self.store.why_not_held(session.id)
        except sqlite3.Error:
            return  # the database is busy or failing: the next round tries again
        if why is not None:
            self._session_lost(why)
        elif self.out_of_order is not None and self._can_write():
            self.out_of_order = None  # space was freed (or the lock let go): the welcome is back
            self._screen_key = None
            self._render()
            self._report_status()

    def _store_failed(self, failed: sqlite3.Error) -> None:
        """The store refused a step (a full disk, a failing drive, a lock held too long; what it
        refused was rolled back, what was stored stays for staff to continue). The kiosk takes no
        patient until it can write again: the patient sees one calm out-of-order screen, staff
        the reason on the clinician screen and the station (:meth:`keep_session` recovers)."""
        self.out_of_order = f"the kiosk could not store its last step ({failed})"
        self._session_lost(self.out_of_order, tell_patient=False)
        self._report_status()

    def _can_write(self) -> bool:
        """The data directory takes :data:`PROBE_BYTES` more (written, synced and removed)."""
        assert self.store is not None
        probe = Path(self.store.path).parent / ".kiosk-write-probe"
        try:
            handle = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
            try:
                os.write(handle, bytes(PROBE_BYTES))
                os.fsync(handle)
            finally:
                os.close(handle)
            return True
        except OSError:
            return False
        finally:
            with contextlib.suppress(OSError):
                probe.unlink()

    def _session_lost(self, reason: str, *, tell_patient: bool = True) -> None:
        """This kiosk may no longer record in its session: say so plainly (naming no one: the next
        patient may be reading) and start over."""
        if tell_patient:
            self.notify(
                f"This test was stopped: {reason}. Staff can see it on the clinician screen.",
                title="Test stopped",
                severity="warning",
                timeout=60,
            )
        if self._new_session is not None:
            self._replace_session(self._new_session())
            self._greet()
        self._screen_key = None
        self._render()

    def set_adaptation(self, enabled: bool) -> None:
        """A clinician switches live adaptation on or off for this session."""
        self._drive(self.session.set_adaptation_enabled, enabled)


# ---------------------------------------------------------------------------------------------
# `kiosk run`


def run_parser() -> argparse.ArgumentParser:
    """The options of `kiosk run` (`kiosk serve` checks what it passes on with it)."""
    parser = argparse.ArgumentParser(prog="kiosk run", description="Start the kiosk (a patient session).")
    parser.add_argument("--data-dir", type=Path, help="where sessions are stored (default: from the configuration)")
    parser.add_argument("--config", type=Path, help="configuration file (default: $KIOSK_CONFIG or the user's)")
    parser.add_argument("--patient", help="the patient's pseudonymous id (default: a new random one)")
    parser.add_argument("--no-voice", action="store_true", help="no spoken prompts and no voice answers")
    parser.add_argument("--no-remote", action="store_true", help="do not look for remote controls")
    return parser


class SetupError(Exception):
    """The kiosk cannot start: a bad configuration, questionnaire, data directory or profile file."""


def build_app(
    *,
    config_path: Path | None = None,
    data_dir: Path | None = None,
    patient_id: str | None = None,
    voice: bool = True,
    remote: bool = True,
) -> tuple[KioskApp, Callable[[], None]]:
    """The kiosk as configured, with whatever channels this machine has, and a function that
    closes what it opened. Raises :class:`SetupError` (one sentence) for a user's mistake."""
    from kiosk.config import ConfigError, configured_questionnaire, load_config, offered_to_patients
    from kiosk.core.adaptation import Adaptation, PolicyError, load_policy
    from kiosk.core.clock import SystemClock
    from kiosk.core.qos_model import load_kiosk_model
    from kiosk.core.questionnaire import QuestionnaireError
    from kiosk.core.visits import STAFF, WALK_UP, VisitDesk
    from kiosk.store.database import PATIENT_ID, StorageError, new_patient_id
    from qos import Engine, ModelError

    if patient_id is not None and not PATIENT_ID.match(patient_id):
        raise SetupError(
            f"--patient {patient_id!r} is not a pseudonymous id: use letters, digits, '-' "
            "and '_' only (2 to 64 characters), never a name"
        )

    try:
        config = load_config(config_path)
        # a site offers patients only validated translations and those it accepts
        questionnaire = offered_to_patients(config, configured_questionnaire(config))
        model = load_kiosk_model(config.qos_model)
        policy = load_policy(config.adaptation_policy, model=model) if config.adaptation else None
        store = Store.open(
            data_dir or config.data_dir,
            interrupt_after_s=config.interrupt_after_minutes * 60,
            outbox=config.station is not None,
            export=export_identity(site_from_config(config)),
            in_force=lambda: in_force_of(config),
        )
        sync = _station_client(config.station, store, lambda command: app.station_command(command))
        # what a kiosk that stopped left running is interrupted now: for staff, never a patient
        store.interrupt_stale()
    except QuestionnaireError as error:
        problems = getattr(error, "problems", None)
        raise SetupError("\n".join(str(p) for p in problems) if problems else str(error)) from None
    except (ConfigError, PolicyError, ModelError, StorageError) as error:
        raise SetupError(str(error)) from None
    statuses: list[ChannelStatus] = []
    keyboard, sources = _remotes(config.remote_profiles, remote, statuses, store)
    speaker = _speaker() if voice else None
    voice_in = _voice_in(config, voice, statuses)
    clock = SystemClock()

    def fresh(
        patient: str | None = None, language: str | None = None, answered_by: str = "patient", visit: str | None = None
    ) -> Session:
        return Session(
            questionnaire,
            clock=clock,
            engine=Engine(model),
            patient_id=patient or new_patient_id(),
            store=store,
            language=language or config.language,
            answered_by=answered_by,
            timing=config.timing,
            adaptation=Adaptation(policy) if policy else None,
            familiarisation=config.familiarisation,
            next_patient_after_s=config.next_patient_after_s,
            visit=visit or (STAFF if patient else WALK_UP),
        )

    def resume(stored: StoredSession) -> Session:
        # the test goes on with the questionnaire it started with, whatever the file says now
        return Session.from_stored(
            questionnaire_of(stored, fallback=questionnaire),
            stored,
            clock=clock,
            engine=Engine(model),
            store=store,
            timing=config.timing,
            adaptation=Adaptation(policy) if policy else None,
            next_patient_after_s=config.next_patient_after_s,
        )

    guard = PinGuard(config.pin_secret, data_dir or config.data_dir)
    visits = VisitDesk(fresh, walk_up=config.walk_up)
    orders, start_order = _station_orders(
        config.station, questionnaire, lambda *found: app.call_from_thread(app.orders_changed, *found)
    )
    app = KioskApp(
        fresh(patient_id),
        clinician_pin=guard,
        store=store,
        speaker=speaker,
        voice=voice_in,
        sources=sources,
        keyboard=keyboard,
        statuses=statuses,
        export_dir=(data_dir or config.data_dir) / "exports",
        export_site=site_from_config(config),
        resume=resume,
        new_session=fresh,
        show_score=config.show_score_to_patient,
        sync=sync,
        visits=visits,
        orders=orders,
        start_order=start_order,
    )
    return app, store.close


def _station_client(station: Any, store: Store, on_command: Callable[[Any], Any]) -> Any:
    """The ward station's client (started with the app), or None when no station is configured."""
    if station is None:
        return None
    from kiosk.sync import SyncClient

    client = SyncClient(
        store.path, url=station.url, token=station.token, kiosk_id=station.kiosk_id, on_command=on_command
    )
    store.on_outbox = client.wake
    return client


def _station_orders(station: Any, questionnaire: Questionnaire, on_orders: Callable[..., None]) -> tuple[Any, Any]:
    """The watcher of this kiosk's ordered visits and the call that starts one with its code, or
    (None, None) without a station (staff then start visits on the clinician screen)."""
    if station is None:
        return None, None
    from kiosk.sync.http import Station
    from kiosk.sync.orders import OrderWatcher, start_order

    instruments, languages = [questionnaire.id], list(questionnaire.languages)
    watcher = OrderWatcher(
        Station(station.url, station.token), instruments=instruments, languages=languages, on_orders=on_orders
    )
    starter = Station(station.url, station.token)
    return watcher, lambda code: start_order(starter, code, instruments=instruments, languages=languages)


def _remotes(
    profiles: Path | None, wanted: bool, statuses: list[ChannelStatus], store: Store
) -> tuple[Any, list[InputSource]]:
    """The keyboard-remote key map and the serial/HID sources, or the reason there are none."""
    if not wanted:
        statuses.append(ChannelStatus(Channel.REMOTE, ChannelState.OFF, "remote", "turned off (--no-remote)"))
        return None, []
    from kiosk.remote import ProfileError, keyboard_remote, open_sources

    try:
        return keyboard_remote(profiles), open_sources(profiles)
    except ProfileError as error:
        store.close()
        raise SetupError(str(error)) from None


def _speaker() -> Any:
    """espeak-ng voice out; it reports on or off (with the reason) once its worker has looked."""
    from kiosk.speech.tts import Speaker

    return Speaker()


def _voice_in(config: Any, wanted: bool, statuses: list[ChannelStatus]) -> Any:
    """The voice-in channel (it reports on, or off with the reason, once started), or None."""
    if not wanted:
        statuses.append(ChannelStatus(Channel.VOICE, ChannelState.OFF, "voice in", "turned off (--no-voice)"))
        return None
    from kiosk.speech.voice import VoiceChannel

    return VoiceChannel(config.language, vosk_model=config.vosk_model)


def main(argv: list[str]) -> int:
    """`kiosk run`: build the session and channels from the configuration and run the app."""
    args = run_parser().parse_args(argv)
    try:
        app, close = build_app(
            config_path=args.config,
            data_dir=args.data_dir,
            patient_id=args.patient,
            voice=not args.no_voice,
            remote=not args.no_remote,
        )
    except SetupError as error:
        print(f"kiosk run: {error}", file=sys.stderr)
        return 2
    if (warning := app.pin_guard.warning) is not None:
        print(f"kiosk run: warning: {warning}", file=sys.stderr)
    try:
        app.run()
    finally:
        close()
    return app.return_code or 0
