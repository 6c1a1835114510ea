"""The staff items of a stored session, for staff to answer on the clinician screen (behind the PIN).

One row per item the instrument marks ``answered_by: staff``: what it has (or "waiting for
staff"), a field for a number (its range and unit beside it) or a choice of its options, and Save.
The widget only reads what staff typed (:func:`kiosk.core.staff.parse_entry`) and posts
:class:`StaffItems.Entered`; the screen stores it. A typing mistake is one line under the row.
"""

from __future__ import annotations

from collections.abc import Mapping

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.widgets import Input, Select

from kiosk.core.questionnaire import Item
from kiosk.core.staff import entry_hint, parse_entry
from kiosk.ui.widgets.literal import Button, Label, literal


class StaffItems(Vertical):
    """Rows for ``items`` (the staff items) in ``language``; ``options`` and ``values`` are what
    staff entered so far (item id -> option number / number)."""

    class Entered(Message):
        """Staff saved an answer: an ``option`` for a choice or a ``value`` for a number."""

        def __init__(self, item_id: str, option: int | None, value: float | None) -> None:
            self.item_id, self.option, self.value = item_id, option, value
            super().__init__()

    def __init__(
        self, items: list[Item], language: str, options: Mapping[str, int], values: Mapping[str, float]
    ) -> None:
        super().__init__(id="staff-items")
        self.items = {item.id: item for item in items}
        self.language = language
        self.options = dict(options)
        self.values = dict(values)

    def _now(self, item: Item) -> str:
        """What the item has now, in a clinician's words."""
        if item.id in self.values and item.entry is not None:
            return f"{self.values[item.id]:g} {item.entry.unit}".strip()
        if item.id in self.options:
            return item.option(self.options[item.id]).label_in(self.language)
        return "waiting for staff"

    def compose(self) -> ComposeResult:
        """A heading, then per item its text and state, the field and Save, and a line for problems."""
        yield Label("Staff items (never shown to the patient):", classes="heading")
        for item in self.items.values():
            yield Label(f"{item.id}: {item.text[self.language]} — {self._now(item)}", id=f"staff-now-{item.id}")
            with Horizontal(classes="staff-row"):
                if item.entry is not None:
                    yield Input(placeholder=entry_hint(item), id=f"staff-value-{item.id}")
                else:
                    choices = [(literal(f"{o.number} {o.label_in(self.language)}"), o.number) for o in item.options]
                    yield Select(choices, prompt="choose", id=f"staff-choice-{item.id}")
                yield Button("Save", id=f"staff-save-{item.id}", classes="staff-save")
            yield Label("", id=f"staff-problem-{item.id}", classes="staff-problem")

    @on(Button.Pressed, ".staff-save")
    def _save(self, event: Button.Pressed) -> None:
        event.stop()
        item = self.items[str(event.button.id).removeprefix("staff-save-")]
        problem = self.query_one(f"#staff-problem-{item.id}", Label)
        if item.entry is not None:
            try:
                value = parse_entry(item, self.query_one(f"#staff-value-{item.id}", Input).value)
            except ValueError as error:
                problem.update(str(error))
                return
            self.post_message(self.Entered(item.id, None, value))
        else:
            chosen = self.query_one(f"#staff-choice-{item.id}", Select).value
            if not isinstance(chosen, int):
                problem.update(f"{item.id}: choose one of its {len(item.options)} options first")
                return
            self.post_message(self.Entered(item.id, chosen, None))
        problem.update("")
