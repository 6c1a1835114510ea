"""A numeric keypad for touch: twelve big keys (1-9, ⌫, 0, OK) in a 3x4 grid, and the same keys
from a keyboard (digits, Backspace, Enter). The clinician's PIN pad and the visit code pad use it;
what is typed, and what OK does with it, is their screen's."""

from __future__ import annotations

from typing import Protocol

from textual import events, on
from textual.containers import Grid

from kiosk.ui.widgets.literal import Button

DELETE = "⌫"
OK = "OK"
#: the pad's keys, in reading order
KEYS = ("1", "2", "3", "4", "5", "6", "7", "8", "9", DELETE, "0", OK)


class Typing(Protocol):
    """What a keypad types into: its screen."""

    def type_digit(self, digit: str) -> None:
        """One digit typed."""

    def delete(self) -> None:
        """Take back the last digit."""

    def submit(self) -> None:
        """OK: what was typed is done."""


def pad_key(button: Button) -> Button:
    """A pad key that takes every tap: a Button ignores a press within its 0.2 s press effect, so
    "0000" typed quickly would lose digits."""
    button.active_effect_duration = 0
    return button


def press(typing: Typing, key: str) -> None:
    """``key`` (one of :data:`KEYS`) pressed: OK submits, ⌫ deletes, a digit is typed."""
    if key == OK:
        typing.submit()
    elif key == DELETE:
        typing.delete()
    else:
        typing.type_digit(key)


def keyboard_key(event: events.Key) -> str | None:
    """The pad's key that a keyboard key stands for: an ASCII digit, ⌫ for Backspace, OK for Enter;
    None for any other key."""
    if event.character is not None and event.character.isdigit() and event.character.isascii():
        return event.character
    return {"backspace": DELETE, "enter": OK}.get(event.key)


class Keypad(Grid):
    """The twelve keys, with ids ``<prefix>key-<digit>``, ``<prefix>key-delete`` and
    ``<prefix>key-ok`` (OK drawn as the primary button); each tap goes to ``typing``."""

    def __init__(self, typing: Typing, *, id: str, prefix: str = "", every_tap: bool = False) -> None:
        """``every_tap``: the keys take a tap that comes during the last one's press effect
        (:func:`pad_key`)."""
        keys = []
        for label in KEYS:
            name = {DELETE: "delete", OK: "ok"}.get(label, label)
            key = Button(label, id=f"{prefix}key-{name}", variant="primary" if label == OK else "default")
            keys.append(pad_key(key) if every_tap else key)
        super().__init__(*keys, id=id)
        self._typing = typing

    @on(Button.Pressed)
    def _pressed(self, event: Button.Pressed) -> None:
        event.stop()
        press(self._typing, str(event.button.label))
