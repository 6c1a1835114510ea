"""Placeholders in the kiosk's words: ``{name}`` and nothing else.

A words file is edited by translators, so its texts are templates, never format strings:
``str.format`` would run ``{ways:>999999999}`` (a gigabyte of spaces on the screen's first
render) or ``{0.__class__}`` (an attribute of an object). :func:`fill` replaces only
``{name}`` marks, and :func:`placeholders` is what ``kiosk validate --words`` checks a text with:
a brace that is not part of a ``{name}`` mark or a doubled ``{{``/``}}`` is a problem.
"""

from __future__ import annotations

import re

__all__ = ["fill", "placeholders"]

#: a doubled brace (a literal one), a {name} mark, or any other brace
_PART = re.compile(r"\{\{|\}\}|\{([A-Za-z_][A-Za-z0-9_]*)\}|\{[^{}]*\}?|\}")


def fill(template: str, **values: object) -> str:
    """``template`` with each ``{name}`` given in ``values`` replaced by its text (``{{`` and
    ``}}`` are a literal brace; a mark not given, or anything else in braces, stays as written)."""

    def one(match: re.Match[str]) -> str:
        part, name = match.group(0), match.group(1)
        if part in ("{{", "}}"):
            return part[0]
        return str(values[name]) if name is not None and name in values else part

    return _PART.sub(one, template)


def placeholders(text: str) -> tuple[set[str], list[str]]:
    """(the names of the ``{name}`` marks in ``text``, every other brace group as written): a text
    whose second part is not empty has a mark :func:`fill` would not fill."""
    names: set[str] = set()
    wrong: list[str] = []
    for match in _PART.finditer(text):
        part, name = match.group(0), match.group(1)
        if name is not None:
            names.add(name)
        elif part not in ("{{", "}}"):
            wrong.append(part)
    return names, wrong
