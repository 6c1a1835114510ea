"""Widgets that show text as it is written, never as Textual markup.

Every text the kiosk shows comes from a file a clinician or translator edits (an instrument,
a words file, a configuration), and "Walks 50 m [with aid]" must read just so: Textual would
parse the brackets as markup, drop them or stop the app with a ``MarkupError``. The kiosk's
screens use no markup of their own, so these stand in for Textual's ``Static``, ``Label`` and
``Button`` everywhere (same names, so styles and queries are unchanged), and :func:`cell` for a
``DataTable`` cell.
"""

from __future__ import annotations

from typing import Any

from rich.markup import escape
from textual import widgets
from textual.content import Content, ContentText

__all__ = ["Button", "Label", "Static", "cell", "literal"]


def literal(text: ContentText) -> Content:
    """``text`` as content shown literally (a ``Content`` given stays as it is)."""
    return Content(text) if isinstance(text, str) else Content.from_text(text)


def cell(text: object) -> str:
    """A ``DataTable`` cell showing ``text`` literally: a string cell is parsed as Rich markup, so
    its brackets are escaped (the cell stays a string, which ``get_row`` gives back)."""
    return escape(str(text))


class Static(widgets.Static):
    """Textual's ``Static``, its content (and every ``update``) shown literally."""

    def __init__(self, content: Any = "", *, markup: bool = False, **kwargs: Any) -> None:
        super().__init__(content, markup=markup, **kwargs)


class Label(widgets.Label):
    """Textual's ``Label``, its content (and every ``update``) shown literally."""

    def __init__(self, content: Any = "", *, markup: bool = False, **kwargs: Any) -> None:
        super().__init__(content, markup=markup, **kwargs)


class Button(widgets.Button):
    """Textual's ``Button``, its label (as given and as later set) shown literally."""

    def validate_label(self, label: ContentText) -> Content:
        return literal(label)
