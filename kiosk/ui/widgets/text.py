"""The kiosk's own screen words (buttons, titles, progress) in each language, from the ``screen``
section of its words file (``kiosk/core/words/<code>.yaml``).

The questionnaire's texts (questions, options, explanations) come from the questionnaire; these are
only the words around them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from kiosk.core.words import TEMPLATE, Table, fill

#: the language whose words every other language falls back to
FALLBACK = TEMPLATE

_SCREENS: Mapping[str, Mapping[str, str]] = Table(lambda words: words.screen)
_NAMES: Mapping[str, str] = Table(lambda words: words.name)


def _table() -> Mapping[str, Mapping[str, str]]:
    return _SCREENS


def ui_text(language: str, key: str, default: str | None = None, **values: object) -> str:
    """The words for ``key`` in ``language`` (English if missing), with ``values`` filled in.

    A key no language has gives ``default``; without one it is a KeyError (a typo in a screen).
    """
    table = _table()
    words = table.get(language, {}).get(key) or table[FALLBACK].get(key, default)
    if words is None:
        raise KeyError(f"no screen text {key!r}")
    return fill(words, **values) if values else words


def language_name(language: str) -> str:
    """The language's own name for itself ("Español"), or its code for a language with no words file."""
    return _NAMES.get(language) or language


def ways_sentence(language: str, sentence: str, ways: Sequence[str], suffix: str = "") -> str:
    """A sentence listing the ways of doing something that are on now, e.g. ``answer_by`` with
    ("touch", "remote"): "Answer by touching it on the screen or pressing its number on the
    remote." Each way's words are ``way_<way><suffix>``; the last two are joined by ``or``."""
    words = ui_text(
        language, sentence, ways=join_or(language, [ui_text(language, f"way_{way}{suffix}") for way in ways])
    )
    return words[0].upper() + words[1:]


def join_or(language: str, phrases: Sequence[str]) -> str:
    """ "a, b or c" in ``language``."""
    if len(phrases) == 1:
        return phrases[0]
    return ", ".join(phrases[:-1]) + f" {ui_text(language, 'or')} {phrases[-1]}"
