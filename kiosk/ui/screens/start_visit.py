"""Staff start a visit for a patient identifier on the kiosk itself (no station, or no order):
an on-screen keyboard for the identifier, the language, whether a relative answers and how the
person answering for the patient is related to them (kept with the result). Behind the PIN."""

from __future__ import annotations

from textual import on
from textual.app import ComposeResult
from textual.containers import Grid, Horizontal, Vertical
from textual.widgets import Switch

from kiosk.core.answerers import RELATIONSHIPS
from kiosk.ui.screens.base import ClinicianScreen
from kiosk.ui.widgets.keypad import pad_key
from kiosk.ui.widgets.literal import Button, Label, Static
from kiosk.ui.widgets.text import language_name

_KEYS = tuple("1234567890ABCDEFGHIJKLMNOPQRSTUVWXYZ-_") + ("⌫",)


#: the relationships staff choose from, and none ("other" needs free text: the station's order carries it)
_CHOICES = ("", *(name for name in RELATIONSHIPS if name != "other"))


def _answering(relationship: str) -> str:
    return f"Answering for the patient: {relationship or 'nobody else'}"


def _key_id(label: str) -> str:
    return {"⌫": "id-key-delete", "-": "id-key-dash", "_": "id-key-underscore"}.get(label, f"id-key-{label}")


class StartVisitScreen(ClinicianScreen):
    """Type the patient's identifier by touch, choose the language, start."""

    DEFAULT_CSS = """
    StartVisitScreen #id-keys { grid-size: 10 4; grid-gutter: 0 0; grid-rows: 3; height: 12; width: 100%; }
    StartVisitScreen #id-keys Button { width: 100%; min-width: 4; height: 3; }
    StartVisitScreen #typed-id { text-style: bold; height: 1; }
    StartVisitScreen #start-visit-error { color: #a4161a; }
    StartVisitScreen Horizontal { height: auto; }
    """
    AUTO_FOCUS = ""

    def __init__(self) -> None:
        super().__init__()
        self._typed = ""
        self._language = ""
        #: how the person answering for the patient is related to them (kiosk.core.answerers), or ""
        self._relationship = ""

    def compose(self) -> ComposeResult:
        app = self.kiosk
        self._language = app.session.language
        with Vertical(classes="clinician"):
            yield Static("Start a visit", classes="heading")
            yield Label("Patient identifier as the hospital gives it (never a name):")
            yield Static(" ", id="typed-id")
            with Grid(id="id-keys"):
                for label in _KEYS:
                    yield pad_key(Button(label, id=_key_id(label)))
            with Horizontal(id="visit-languages"):
                for language in app.questionnaire.languages:
                    yield Button(
                        language_name(language),
                        id=f"visit-lang-{language}",
                        variant="primary" if language == self._language else "default",
                    )
                yield Label("A relative answers")
                yield Switch(value=False, id="visit-relative")
            with Horizontal():
                yield Button("Start the visit", id="start-visit-go", variant="success")
                yield Button("Back", id="start-visit-back")
                yield Button(_answering(""), id="visit-relationship")
            yield Label("", id="start-visit-error")

    def type_key(self, label: str) -> None:
        if label == "⌫":
            self._typed = self._typed[:-1]
        elif len(self._typed) < 64:
            self._typed += label
        self.query_one("#typed-id", Static).update(self._typed or " ")

    @on(Button.Pressed, "#id-keys Button")
    def _key(self, event: Button.Pressed) -> None:
        event.stop()
        self.type_key(str(event.button.label))

    @on(Button.Pressed, "#visit-languages Button")
    def _choose_language(self, event: Button.Pressed) -> None:
        event.stop()
        self._language = (event.button.id or "").removeprefix("visit-lang-")
        for button in self.query("#visit-languages Button").results(Button):
            button.variant = "primary" if button is event.button else "default"

    @on(Button.Pressed, "#visit-relationship")
    def _next_relationship(self, event: Button.Pressed) -> None:
        """Each press shows the next relationship, then none again (one button fits any screen)."""
        event.stop()
        self._relationship = _CHOICES[(_CHOICES.index(self._relationship) + 1) % len(_CHOICES)]
        event.button.label = _answering(self._relationship)

    @on(Button.Pressed, "#start-visit-go")
    def _go(self, event: Button.Pressed) -> None:
        event.stop()
        relative = self.query_one("#visit-relative", Switch).value
        refused = self.kiosk.controller.start_staff_visit(
            self._typed, self._language, relative, relationship=self._relationship or None
        )
        if refused:
            self.query_one("#start-visit-error", Label).update(f"Not started: {refused}")

    @on(Button.Pressed, "#start-visit-back")
    def _back(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss()
