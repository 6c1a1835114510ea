"""What every patient screen shares: the view it renders, the top bar, the notices, the way it
forwards keys, and the sizes it adapts its layout to."""

from __future__ import annotations

from collections.abc import Hashable
from typing import TYPE_CHECKING, Protocol, cast

from textual import events, on
from textual.app import ComposeResult
from textual.containers import Horizontal
from textual.screen import Screen

from basis import record
from kiosk.core.adaptation import VOICE_OFF
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.session import ATTEMPTS, Phase, Snapshot
from kiosk.ui.widgets.bars import AdaptationBanner, VoiceAgainButton
from kiosk.ui.widgets.literal import Button, Label
from kiosk.ui.widgets.text import join_or, ui_text, ways_sentence
from kiosk.ui.widgets.waiting_sign import WaitingSign

if TYPE_CHECKING:
    from pathlib import Path

    from kiosk.core.pin import PinGuard
    from kiosk.core.session import Session
    from kiosk.ui.controller import KioskController
    from kiosk.ui.widgets.channel_board import ChannelBoard


class KioskHost(Protocol):
    """What a screen may use of the running app (:class:`~kiosk.ui.app.KioskApp` has it): stated
    here, so the screens need nothing of the app's module and the app imports its screens alone."""

    controller: KioskController
    board: ChannelBoard
    pin_guard: PinGuard
    export_dir: Path | None
    questionnaire: Questionnaire

    @property
    def session(self) -> Session: ...
    def patient_key(self, key: str) -> bool: ...
    def close_clinician(self) -> None: ...
    def quit_kiosk(self) -> None: ...


#: screen heights (rows) from which a patient screen uses its roomy layout: padded text and the
#: big block digits on the answers; below, it packs everything tighter (a 1024x600 panel at a
#: large font is about 18 rows, an 80x24 terminal 24)
ROOMY_ROWS = 28
#: screen widths (columns) from which the top bar also shows the ways the patient can answer
WIDE_COLUMNS = 90


@record
class Ways:
    """The ways the patient can act right now, as the channels are: what instructions may promise.

    ``voice`` means voice answers are heard (voice in works and adaptation has not paused it);
    ``listening`` that the kiosk listens at this very moment (the welcome screen only promises
    "say English" then); ``voice_out`` that the kiosk can speak (Repeat is only offered then).
    """

    remote: bool = False
    voice: bool = False
    listening: bool = False
    voice_out: bool = False

    def answering(self) -> tuple[str, ...]:
        """The ways of answering a question: touch always, then the remote and voice when on."""
        return ("touch",) + (("remote",) if self.remote else ()) + (("voice",) if self.voice else ())


@record
class PatientView:
    """Everything a patient screen draws: the session's snapshot plus what the app knows around it."""

    snapshot: Snapshot
    questionnaire: Questionnaire
    #: what the channels allow now (the instructions are built from it)
    ways: Ways = Ways()
    #: offer "Answer by voice again" (voice is switched off by adaptation and voice in works)
    voice_again: bool = False
    #: the number of answers of the question on screen, when the patient pressed a number it
    #: does not have (a gentle "Please choose 1, 2 or 3" follows)
    hint_options: int | None = None
    #: session time now (the waiting sign's slow dot follows it)
    now: float = 0.0
    #: the end screen shows the total and band (a site's choice; default: staff only)
    show_score: bool = False
    #: the page of a 5- or 6-answer item a remote is on (0: options 1-3; :mod:`kiosk.ui.paging`)
    remote_page: int = 0

    @property
    def waiting(self) -> bool:
        """An answer is awaited now (an attempt is open and nothing stops the clock)."""
        snap = self.snapshot
        return snap.attempt is not None and not (snap.paused or snap.halted) and snap.person_present


def spoken_with_ways(spoken: str, language: str, ways: Ways) -> str:
    """A prompt's spoken words with ``{ways}`` replaced by how to choose an answer with the channels
    on now ("Touch it, press its number on the remote or say its number."), so the voice never
    promises a remote or a microphone that is off."""
    if "{ways}" not in spoken:
        return spoken
    return spoken.replace("{ways}", ways_sentence(language, "choose_by", ways.answering(), "_select"))


def patient_notices(view: PatientView) -> str | None:
    """The notices the patient sees above the question, in their language, or None: only what is
    true with the channels on now (no "speaking more slowly" without a voice)."""
    snap, lang = view.snapshot, view.snapshot.language
    if not snap.person_present:  # away: one calm message, nothing else
        return ui_text(lang, "person_lost")
    notices = []
    if view.hint_options:
        options = [str(n) for n in range(1, view.hint_options + 1)]
        notices.append(ui_text(lang, "only_options", options=join_or(lang, options)))
    for name in sorted(snap.adaptations):
        if name == "slow_speech" and not view.ways.voice_out:
            continue
        if name in VOICE_OFF:  # this patient's voice, or this room: the patient reads the same
            if name != min(VOICE_OFF & snap.adaptations):
                continue  # said once when both are on
            ways = ("touch", "remote") if view.ways.remote else ("touch",)
            notices.append(ways_sentence(lang, "voice_off", ways, "_answer"))
            continue
        # the patient's words come from their language's text, or there is no notice: a policy's
        # name ("longer_attempts") is never shown
        words = view.questionnaire.message(name, lang) or ui_text(lang, name, default="")
        if words:
            notices.append(words)
    return " ".join(notices) or None


class KioskScreen(Screen):
    """Base of every kiosk screen: :attr:`kiosk` is the running app with its own type."""

    @property
    def kiosk(self) -> KioskHost:
        """``self.app`` as the kiosk it always is (Textual types it as any App); a screen reads the
        session and asks the controller through it."""
        return cast(KioskHost, self.app)


class PatientScreen(KioskScreen):
    """Base of the patient's screens: built from a view, refreshed in place by :meth:`show`.

    The app switches to a new screen only when :meth:`key` of the new view differs (another
    phase, question or language); otherwise it calls :meth:`show` so a tick of the clock or a
    channel change does not rebuild the screen. The screen carries the class ``-roomy`` when it
    is tall enough for the spacious layout, ``-wide`` when wide enough for the ways row; the
    stylesheet packs everything tighter otherwise, so every screen fits without scrolling.
    """

    #: nothing starts focused: a focused answer would look chosen; keys and touch need no focus
    AUTO_FOCUS = ""
    HORIZONTAL_BREAKPOINTS = [(0, "-narrow"), (WIDE_COLUMNS, "-wide")]
    #: the screen asks the patient for an answer (its top bar shows the ways they can give one)
    ASKS = False
    VERTICAL_BREAKPOINTS = [(0, "-short"), (ROOMY_ROWS, "-roomy")]
    #: the screen shows the notices banner (the end screen does not: it no longer concerns the patient)
    NOTICES = True
    #: the top bar shows "Attempt 1 of 2" (not while the doctor is called: nothing is being asked)
    SHOWS_ATTEMPT = True

    def __init__(self, view: PatientView) -> None:
        """Build the screen for ``view``."""
        super().__init__()
        self.view = view

    @classmethod
    def key(cls, view: PatientView) -> Hashable:
        """What makes two views need different screens of this class (default: the language)."""
        return view.snapshot.language

    @property
    def language(self) -> str:
        """The language the screen is drawn in."""
        return self.view.snapshot.language

    def compose_bars(self) -> ComposeResult:
        """Progress, the ways to answer and the attempt; the notice banner and its voice-again
        button. No channel or device words: those are for the clinician's screens."""
        with Horizontal(id="topbar"):
            yield Label("", id="progress")
            yield Label("", id="ways")
            yield Label("", id="attempt")
        yield AdaptationBanner(id="banner")
        yield VoiceAgainButton(self.language)

    def on_mount(self) -> None:
        """Fill the bars once they exist."""
        self.show(self.view)

    def show(self, view: PatientView) -> None:
        """Refresh the parts that change within one screen (bars, banner, attempt)."""
        self.view = view
        snap = view.snapshot
        for progress in self.query("#progress").results(Label):
            progress.update(self.progress_text(view))
        for attempt in self.query("#attempt").results(Label):
            attempt.update(
                ui_text(self.language, "attempt_of", number=snap.attempt, total=ATTEMPTS)
                if snap.attempt and self.SHOWS_ATTEMPT
                else ""
            )
        for ways in self.query("#ways").results(Label):
            ways.update(self.ways_text(view))
        for banner in self.query(AdaptationBanner):
            banner.show(patient_notices(view) if self.NOTICES else None)
        for button in self.query(VoiceAgainButton):
            button.show(view.voice_again)
        for sign in self.query(WaitingSign):
            sign.show(view.waiting, view.now)

    def ways_text(self, view: PatientView) -> str:
        """The calm row of the ways the patient can answer: "You can: touch · remote · speak", on
        the screens that ask for an answer (:attr:`ASKS`)."""
        if not self.ASKS:
            return ""
        words = [ui_text(self.language, f"ways_{way}") for way in view.ways.answering()]
        return f"{ui_text(self.language, 'ways_title')} {' · '.join(words)}"

    def progress_text(self, view: PatientView) -> str:
        """The left of the top bar: "Question 3 of 10" while a question is under way (also on the
        paused and doctor-called screens over it), else the questionnaire's title."""
        snap = view.snapshot
        if snap.number is None:
            title = view.questionnaire.title_for_patient(self.language)
            if snap.part is not None and snap.phase is not Phase.WELCOME:  # between a visit's instruments
                part = ui_text(self.language, "part_of", number=snap.part[0], total=snap.part[1])
                return f"{part} · {title}"
            return title
        return ui_text(self.language, "question_of", number=snap.number, total=snap.count)

    def on_key(self, event: events.Key) -> None:
        """Hand kiosk keys (1-4, the control letters, a keyboard remote's keys) to the app. The
        letters shown on the controls in this language (M for "Llamar al médico") stand for the
        kiosk's own P, R and D, which keep working in every language."""
        key = event.key
        for command, letter in (("pause", "p"), ("repeat", "r"), ("call_doctor", "d")):
            if key.removeprefix("shift+").lower() == ui_text(self.language, f"key_{command}"):
                key = letter
        if self.kiosk.patient_key(key):
            event.stop()
            event.prevent_default()


class PageButton(Button):
    """Up or Down: every tap pages, also one that comes while the last tap still shows (a plain
    Button ignores a tap during its 0.2 s pressed look, so quick taps would be lost)."""

    async def _on_click(self, event: events.Click) -> None:
        event.stop()
        self.press()


def staff_nav(back: str = "Back to the patient") -> ComposeResult:
    """The bar at the bottom of a staff screen: the way back, and Up/Down that page its scrolling
    body (a finger on the served display has no wheel)."""
    with Horizontal(id="staff-nav"):
        yield Button(back, id="back", variant="primary")
        yield PageButton("▲ Up", id="page-up")
        yield PageButton("▼ Down", id="page-down")


class ClinicianScreen(KioskScreen):
    """Base of the screens behind the PIN; the patient's screen waits underneath until they close.
    A screen with :func:`staff_nav` pages its ``.staff-body`` with Up and Down."""

    #: their rules, read when the first of them is shown (beside this module): not at the welcome
    CSS_PATH = "staff.tcss"
    BINDINGS = [("escape", "close", "Back")]

    @on(Button.Pressed, "#page-up")
    def _page_up(self, event: Button.Pressed) -> None:
        event.stop()
        self._page(-1)

    @on(Button.Pressed, "#page-down")
    def _page_down(self, event: Button.Pressed) -> None:
        event.stop()
        self._page(1)

    def _page(self, direction: int) -> None:
        """Scroll the body by half its height: whatever is shorter than that is wholly in view
        at some tap (a full page would step over a table straddling the fold)."""
        for body in self.query(".staff-body"):
            body.scroll_relative(y=direction * max(1, body.size.height // 2), animate=False)

    def action_close(self) -> None:
        """Go back one clinician screen (from the first one, back to the patient)."""
        self.dismiss()
