"""The welcome when a visit is ordered for this kiosk (or when the site allows no walk-up): that a
visit is ready, and a pad for staff to type the code the ward station shows on the order's page.
The code is staff's confirmation that the patient in front of the kiosk is the ordered one; the
screen never names the patient (anyone passing by reads it), only something neutral of each visit.

The screen only renders and forwards: a typed code goes to the app (:class:`CodeEntered`), which
asks the station; the answer comes back through :meth:`refused` or a new session.
"""

from __future__ import annotations

from textual import events, on
from textual.app import ComposeResult
from textual.containers import Vertical
from textual.message import Message

from kiosk.core.visits import Order
from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.widgets.keypad import Keypad, keyboard_key, press
from kiosk.ui.widgets.literal import Button, Label, Static
from kiosk.ui.widgets.text import language_name

CODE_DIGITS = 4


def order_line(number: int, order: Order) -> str:
    """One ordered visit as anyone passing may read it: its place, how many questionnaires, the
    language; never the patient's identifier nor the instruments (issue 36: passers-by)."""
    count = len(order.instruments)
    return f"Visit {number} · {count} questionnaire{'s' if count != 1 else ''} · {language_name(order.language)}"


class VisitReadyScreen(PatientScreen):
    """The ordered visits and the code pad; with walk-ups allowed, also a way to start one."""

    DEFAULT_CSS = """
    VisitReadyScreen #visit-ready { height: 1fr; padding: 0 2; }
    VisitReadyScreen .visit-heading { text-style: bold; padding: 1 0 0 0; }
    VisitReadyScreen #visit-code { text-style: bold; height: 1; }
    VisitReadyScreen #visit-error { color: #a4161a; }
    VisitReadyScreen Static { width: 1fr; }
    VisitReadyScreen #visit-keys { grid-size: 3 4; grid-gutter: 0 1; grid-columns: 12; grid-rows: 3;
                                   width: 40; height: 12; }
    VisitReadyScreen #visit-keys Button { width: 12; height: 3; min-width: 8; }
    """

    class CodeEntered(Message):
        """Staff typed a visit's code and pressed OK."""

        def __init__(self, code: str) -> None:
            self.code = code
            super().__init__()

    class WalkUpChosen(Message):
        """Staff chose a test without an order for the person in front of the kiosk."""

    def __init__(self, view: PatientView, orders: tuple[Order, ...], walk_up: bool) -> None:
        super().__init__(view)
        self.orders = orders
        self.walk_up = walk_up
        self._typed = ""

    def compose(self) -> ComposeResult:
        yield from self.compose_bars()
        with Vertical(id="visit-ready"):
            if self.orders:
                yield Static("A visit is ready", classes="visit-heading", id="visit-heading")
                for number, order in enumerate(self.orders, 1):
                    yield Static(order_line(number, order), classes="visit-order")
                yield Static("Staff: with the patient here, type the code the ward station shows for this visit.")
                yield Static(" ", id="visit-code")
                yield Label("", id="visit-error")
                yield Keypad(self, id="visit-keys", prefix="visit-", every_tap=True)
            else:
                yield Static("No visit is ready on this kiosk", classes="visit-heading", id="visit-heading")
                yield Static("Staff: order a visit on the ward station, or start one on the clinician screen.")
            if self.walk_up:
                yield Button("Start a test without an order", id="walk-up")

    def progress_text(self, view: PatientView) -> str:
        return " · ".join(dict.fromkeys(view.questionnaire.title.values()))

    def _show_code(self) -> None:
        for code in self.query("#visit-code").results(Static):
            code.update(" ".join(self._typed) or " ")

    def type_digit(self, digit: str) -> None:
        if len(self._typed) < CODE_DIGITS:
            self._typed += digit
            self._show_code()

    def delete(self) -> None:
        self._typed = self._typed[:-1]
        self._show_code()

    def submit(self) -> None:
        if len(self._typed) == CODE_DIGITS:
            self.post_message(self.CodeEntered(self._typed))
            self.query_one("#visit-error", Label).update("Checking with the ward station…")
        else:
            self.query_one("#visit-error", Label).update(f"The code has {CODE_DIGITS} digits.")

    def refused(self, why: str) -> None:
        """The station did not start the visit: say why and empty the code."""
        self._typed = ""
        self._show_code()
        for error in self.query("#visit-error").results(Label):
            error.update(why)

    @on(Button.Pressed, "#walk-up")
    def _walk_up(self, event: Button.Pressed) -> None:
        event.stop()
        self.post_message(self.WalkUpChosen())

    def on_key(self, event: events.Key) -> None:
        """Digits type the code (never a remote's answer: nothing starts here without staff)."""
        if not self.orders or (key := keyboard_key(event)) is None:
            return
        press(self, key)
        event.stop()
        event.prevent_default()
