"""The kiosk's Textual app: mounts the screens, routes input to the controller, draws the session.

Nothing is decided here. Every input (a touch, a key, a remote press, a voice answer) goes to the
:class:`~kiosk.ui.controller.KioskController` as a :class:`~kiosk.core.channels.ChannelInput`;
the controller swaps, holds and ends sessions and asks for a redraw. A timer polls the session
so its time-outs happen on its injected clock. Channels run on their own threads and only call
:meth:`KioskApp.channel_sink`, which posts a message to the UI thread: no thread touches a widget.
Build the app with :func:`kiosk.ui.compose.make_kiosk`; `kiosk run` is :mod:`kiosk.commands.run`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

from textual import events
from textual.app import App
from textual.binding import Binding
from textual.message import Message
from textual.reactive import Reactive

from kiosk.core.channels import Channel, ChannelInput, ChannelStatus, Command, Presence
from kiosk.core.pin import CornerTaps, PinGuard
from kiosk.core.session import Phase, Session, SessionEvent
from kiosk.core.site import ExportSite
from kiosk.store.lease import LEASE_TTL_S
from kiosk.ui.channels import KioskChannels
from kiosk.ui.controller import KioskController
from kiosk.ui.screens.base import ClinicianScreen, PatientScreen, PatientView
from kiosk.ui.screens.welcome import WelcomeScreen
from kiosk.ui.stage import PatientStage, patient_view
from kiosk.ui.widgets.bars import ControlBar, VoiceAgainButton
from kiosk.ui.widgets.channel_board import REMOTE, VOICE_IN, VOICE_OUT
from kiosk.ui.widgets.waiting_sign import WaitingSign

if TYPE_CHECKING:  # message types of screens loaded when first shown (kiosk.ui.stage), not before the welcome
    from kiosk.ui.screens.doctor_called import DoctorCalledScreen
    from kiosk.ui.screens.explanation import ExplanationScreen
    from kiosk.ui.screens.unattended import UnattendedScreen
    from kiosk.ui.screens.visit_ended import VisitEndedScreen
    from kiosk.ui.screens.visit_ready import VisitReadyScreen
    from kiosk.ui.widgets.answer_button import AnswerButton
    from kiosk.ui.widgets.change_answer import ChangeAnswerButton

#: the kiosk display's size in cells (columns, rows): snapshots and the bench use it
KIOSK_SIZE = (100, 32)
#: the clinician screens open with this chord, then ask for the PIN
CLINICIAN_CHORD = "ctrl+k"
#: how often the session is polled for time-outs (seconds); it fires them at their own due time
POLL_INTERVAL = 0.1
#: seconds the PIN pad waits for a touch or key before it goes back to the patient (a patient who
#: tapped the corner five times is not left on it)
PIN_IDLE_S = 60.0
#: the same for the clinician screens behind the PIN (staff walked away: the patient's screen returns)
CLINICIAN_IDLE_S = 300.0


@dataclass
class ChannelReceived(Message):
    """A channel thread delivered an input or a status change (posted, never handled on that thread)."""

    item: ChannelInput | ChannelStatus | Presence


@dataclass
class VoiceUnheard(Message):
    """Voice in heard speech it could not take: not an answer or command, or too unsure."""

    reason: str


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

    ``controller`` runs the sessions (its first one not yet started); ``channels`` are the ways in
    and out besides touch (their sources start with :meth:`channel_sink` on mount, stop on exit).
    With a store, the controller's lease on its session is renewed every third of :data:`LEASE_TTL_S`.
    """

    CSS_PATH = "kiosk.tcss"
    TITLE = "Barthel kiosk"
    #: no text selection: taps (the five on the staff corner) must not leave a highlighted word
    ALLOW_SELECT = False
    BINDINGS = [Binding(CLINICIAN_CHORD, "clinician", "Clinician", show=False, priority=True)]
    ENABLE_COMMAND_PALETTE = False
    #: the clinician's widgets (tables, switches, the plot) follow the theme: light like the rest.
    #: A default, not set in ``__init__``: setting it there parses the whole stylesheet twice
    theme: Reactive[str] = Reactive("textual-light")

    def __init__(
        self,
        controller: KioskController,
        channels: KioskChannels | None = None,
        *,
        clinician_pin: str | PinGuard,
        export_dir: Path | None = None,
        export_site: ExportSite | None = None,
        poll_interval: float = POLL_INTERVAL,
        show_score: bool = False,
    ) -> None:
        super().__init__()
        self.controller = controller
        self.questionnaire = controller.session.questionnaire
        #: checks the clinician PIN (a plain string: an in-memory guard, for tests and benches)
        self.pin_guard = clinician_pin if isinstance(clinician_pin, PinGuard) else PinGuard(clinician_pin)
        #: on the kiosk's own clock, so the taps' gaps are the kiosk's time, not a loaded machine's
        self._corner = CornerTaps(now=lambda: self.session.clock.now())
        self.channels = channels = channels or KioskChannels()
        #: the latest status of every channel (the channel bar and the clinician screen show it)
        self.board = channels.board
        self.export_dir = export_dir
        #: the site and kiosk the clinician's exports name (the same identifiers as `kiosk results`)
        self.export_site = export_site or ExportSite()
        self.poll_interval = poll_interval
        #: the end screen shows the patient their total and band (config show_score_to_patient)
        self.show_score = show_score
        if (speaker := channels.speaker) is not None:  # its worker thread reports through these
            speaker.on_status, speaker.on_speech = self.channel_sink, self.speaker_activity
        if channels.voice is not None and hasattr(channels.voice, "on_unmatched"):
            channels.voice.on_unmatched = self.voice_unheard  # counted for the room (kiosk.core.room)
        self.stage = PatientStage(self)
        #: session time of the last touch or key on a staff screen (their idle time-out counts from it)
        self._staff_seen = 0.0
        #: the app is unmounting: threads not started by now are never started
        self._unmounted = False
        #: the language of a visit the ward cancelled while it ran: its calm end shows until a touch
        self.visit_ended: str | None = None
        #: called once the welcome is drawn, before the channels start (`kiosk run` resumes the
        #: garbage collector it paused for the start)
        self.after_first_frame: list[Callable[[], None]] = []
        controller.attach(self)
        controller.remote_in_use = lambda: self.channels.on(REMOTE)  # 5-6 answers show pages then
        self.tell_channels()

    @property
    def session(self) -> Session:
        """The session running now (the controller's)."""
        return self.controller.session

    # -- start and stop -------------------------------------------------------------------------

    def on_mount(self) -> None:
        """Start the poll timer and show the welcome screen; the channels and the station's client
        start once it is drawn (:meth:`_start_threads`)."""
        self.set_interval(self.poll_interval, self.poll_session)
        if self.controller.store is not None:
            self.set_interval(LEASE_TTL_S / 3, self.controller.keep_session)
        self.controller.greet()
        self.controller.display_size(*self.size)
        self._render()
        self.call_after_refresh(self._start_threads)

    def on_resize(self, event: events.Resize) -> None:
        """The display changed size: below the kiosk's floor it takes no patient, and says why."""
        self.controller.display_size(event.size.width, event.size.height)

    def _start_threads(self) -> None:
        """Start the speaker, the input sources and the station's client, after the first frame:
        their threads (numpy, PortAudio, device probes) would otherwise hold the GIL while the
        patient waits for the welcome. What the session said before is queued for the speaker."""
        if self._unmounted:
            return
        for call in self.after_first_frame:
            call()
        if self.channels.speaker is not None:
            self.channels.speaker.start()
        for source in self.channels.input_sources():
            # loading a speech model or probing a device can take a while: never on the UI thread
            self.run_worker(
                partial(source.start, self.channel_sink), thread=True, name=f"start {source.name}", group="channels"
            )
        self.controller.start_station()

    def on_unmount(self) -> None:
        """Stop every channel (each stop is safe to call twice, and before a start) and the
        station's client."""
        self._unmounted = True
        self.controller.stop_station()
        self.channels.close()

    # -- from other threads -----------------------------------------------------------------------

    def channel_sink(self, item: ChannelInput | ChannelStatus | Presence) -> None:
        """The sink every channel (and the speaker's status) delivers to, from its own thread:
        posts to the UI thread. The camera delivers its presence reports here too."""
        self.post_message(ChannelReceived(item))

    def voice_unheard(self, utterance: str, reason: str) -> None:
        """Voice in heard speech it could not take (on its own thread): posted to the UI thread."""
        self.post_message(VoiceUnheard(reason))

    def on_voice_unheard(self, message: VoiceUnheard) -> None:
        """The session counts it against how well voice is heard in this room."""
        self.controller.drive(self.session.voice_unheard, message.reason)

    def speaker_activity(self, speaking: bool) -> None:
        """The speaker's speech start/end callback (worker thread). The recogniser is muted right
        here, not after the hop to the UI thread, so none of the kiosk's own voice reaches it."""
        if self.channels.voice is not None:
            self.channels.voice.set_muted(speaking)
        self.post_message(SpeechActivity(speaking))

    def station_command(self, command: Any) -> tuple[str, str | None] | None:
        """A command from the ward station (called on the client's thread): applied on the UI thread."""
        return self.call_from_thread(self.controller.station_command, command)

    def visit_cancelled(self, order_ids: tuple[str, ...]) -> None:
        """The ward cancelled these visits (the order watcher, handed over to the UI thread): a
        running one ends and its patient reads a calm end until someone touches the screen."""
        from kiosk.sync.commands import end_cancelled

        if (language := end_cancelled(self.controller, order_ids)) is not None:
            self.visit_ended = language
            self.redraw(rebuild=True)

    def on_visit_ended_screen_dismissed(self, message: VisitEndedScreen.Dismissed) -> None:
        self.visit_ended = None
        self.redraw(rebuild=True)

    def on_channel_received(self, message: ChannelReceived) -> None:
        """An input goes to the session; a status change to the channel bar."""
        if isinstance(message.item, ChannelStatus):
            self.board.update(message.item)
            if self.channels.about_voice(message.item):
                self.controller.drive(self.tell_channels)
            self._render()
        else:
            self.controller.forward(message.item)

    def on_speech_activity(self, message: SpeechActivity) -> None:
        """Show "speaking", and tell the session once a repeated prompt has been said."""
        if self.channels.speaking(message.speaking):
            self.controller.drive(self.session.prompt_delivered)
        else:
            self._render()

    # -- from the screens (UI thread) -------------------------------------------------------------

    def patient_key(self, key: str) -> bool:
        """A key pressed on a patient screen; True if it meant something to the kiosk."""
        if (item := self.channels.key_input(key)) is None:
            return False
        self.controller.forward(item)
        return True

    def on_answer_button_chosen(self, message: AnswerButton.Chosen) -> None:
        """A touched answer is a touch input; the page button (no option) shows the other answers."""
        if message.option is None:
            self.controller.turn_page()
            return
        self.controller.forward(ChannelInput(Channel.TOUCH, option=message.option, detail="screen"))

    def on_control_bar_commanded(self, message: ControlBar.Commanded) -> None:
        """A touched Pause/Continue/Repeat/Call-doctor is a touch command."""
        self.controller.forward(ChannelInput(Channel.TOUCH, command=message.command, detail="screen"))

    def on_change_answer_button_requested(self, message: ChangeAnswerButton.Requested) -> None:
        """ "Change my answer" is the undo command, by touch; the session decides if it still can."""
        self.controller.forward(ChannelInput(Channel.TOUCH, command=Command.UNDO, detail="screen"))

    def on_voice_again_button_requested(self, message: VoiceAgainButton.Requested) -> None:
        """The patient asked to answer by voice again; the session decides."""
        self.controller.drive(self.session.request_voice)

    def on_welcome_screen_language_chosen(self, message: WelcomeScreen.LanguageChosen) -> None:
        """Start in the language the patient touched."""
        self.controller.start_in(message.language)

    def on_doctor_called_screen_carry_on(self, message: DoctorCalledScreen.CarryOn) -> None:
        """The patient touched "I'm fine, carry on" after calling the doctor."""
        self.controller.drive(self.session.cancel_doctor_call, Channel.TOUCH)

    def on_unattended_screen_go_on(self, message: UnattendedScreen.GoOn) -> None:
        """Someone touched the screen while the kiosk waited for a touch: the test goes on."""
        self.controller.forward(ChannelInput(Channel.TOUCH, option=1, detail="screen"))

    def on_explanation_screen_understood(self, message: ExplanationScreen.Understood) -> None:
        """The patient touched Start under the explanation."""
        self.controller.drive(self.session.acknowledge)

    def on_visit_ready_screen_walk_up_chosen(self, message: VisitReadyScreen.WalkUpChosen) -> None:
        self.controller.walk_up()

    def on_visit_ready_screen_code_entered(self, message: VisitReadyScreen.CodeEntered) -> None:
        """Staff typed a visit's code: the station says which visit it starts (off the UI thread)."""
        if (starter := self.controller.start_order) is None:
            return

        def ask() -> None:
            try:
                order = starter(message.code)
            except Exception as refused:  # OrderRefused or Unreachable: said to staff
                self.call_from_thread(self._order_refused, str(refused) or type(refused).__name__)
                return
            self.call_from_thread(self.controller.order_started, order)

        self.run_worker(ask, thread=True, name="start an order", group="orders")

    def _order_refused(self, why: str) -> None:
        from kiosk.ui.screens.visit_ready import VisitReadyScreen  # loaded: it asked for the order

        if isinstance(self.screen, VisitReadyScreen):
            self.screen.refused(why if why.endswith(".") else f"The ward station cannot be reached ({why}).")

    def poll_session(self) -> None:
        """Let the session's due time-outs happen (the poll timer calls this), and move the
        waiting sign's dot on with the session's clock. Nothing while no screen is up: the timer
        can still fire while the app is closing (as when another kiosk holds the test)."""
        if not self.screen_stack:
            return
        if self.controller.tugs is not None:
            self.controller.tugs.poll()
        if self.controller.tug_busy:  # the session waits (not yet started, or finished)
            for screen in self.screen_stack:
                getattr(screen, "tick", lambda: None)()  # the TUG's screens follow the run
        else:
            self.controller.drive(self.session.poll)
        self._staff_idle()
        if isinstance(self.screen, PatientScreen):
            for sign in self.screen.query(WaitingSign):
                sign.tick(self.session.now())

    # -- what the controller asks of the UI (kiosk.ui.controller.Screens) --------------------------

    def redraw(self, *, rebuild: bool = False) -> None:
        """Show the screens the session calls for (``rebuild``: even if they look the same)."""
        if rebuild:
            self.stage.forget()
        self._render()

    def session_event(self, event: SessionEvent) -> None:
        """Carry out what an event asks of the channels; the redraw follows the operation."""
        self.channels.follow(event, lambda: self._view().ways)

    def tell_channels(self) -> None:
        """Tell the session whether voice in and voice out are on (it decides what that means for
        adaptation and for the practice questions)."""
        self.session.set_voice_available(self.channels.on(VOICE_IN))
        self.session.set_voice_out_available(self.channels.on(VOICE_OUT))

    def stopped(self, reason: str) -> None:
        """A plain notice that the test stopped (naming no one: the next patient may be reading)."""
        self.notify(
            f"This test was stopped: {reason}. Staff can see it on the clinician screen.",
            title="Test stopped",
            severity="warning",
            markup=False,
            timeout=60,
        )

    def later(self, callback: Callable[[], None]) -> None:
        self.call_later(callback)

    # -- drawing -------------------------------------------------------------------------------

    def _view(self) -> PatientView:
        # the running session's instrument: a battery's changes from one instrument to the next
        return patient_view(
            self.session,
            self.channels,
            self.session.questionnaire,
            show_score=self.show_score,
            remote_page=self.controller.remote_page(),
        )

    def _render(self) -> None:
        """Show the screens the session's state calls for (none over the clinician's)."""
        if self.is_running and not self.clinician_open:
            held = self.controller.visits if self.controller.welcome_held() else None
            tug = self.controller.tugs if self.controller.tug_busy else None
            if self.session.phase is not Phase.WELCOME:
                self.visit_ended = None  # a new visit began (staff started one): its screens show
            self.stage.show(
                self._view(),
                out_of_order=self.controller.out_of_order is not None,
                held_visits=held,
                tug=tug,
                ended=self.visit_ended,
            )

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
            if ok:  # its table, switches and the stored tests' exports load when staff first get in
                from kiosk.ui.screens.clinician_home import ClinicianHomeScreen

                self.push_screen(ClinicianHomeScreen())
                if (tugs := self.controller.tugs) is not None and tugs.busy:  # the visit's TUG waits for staff
                    from kiosk.ui.screens.tug_staff import TugStaffScreen

                    self.push_screen(TugStaffScreen(tugs))
            else:
                self.controller.release()

        from kiosk.ui.screens.pin import PinScreen  # the PIN pad loads when staff first ask for it

        self._staff_seen = self.session.now()
        self.push_screen(PinScreen(self.pin_guard), unlocked)
        self.controller.hold()

    def _staff_idle(self) -> None:
        """Back to the patient once the staff screens have had no touch or key for their idle time
        (the session's clock: a simulated one in tests and replays)."""
        if not self.clinician_open:
            return
        from kiosk.ui.screens.pin import PinScreen  # loaded: the clinician screens are open

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
        self.controller.release()
        self.stage.forget()
        self.call_after_refresh(self._render)
