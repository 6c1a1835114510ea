"""The kiosk's own screen words (buttons, titles, progress) in each language, from ``ui_text.yaml``.

The questionnaire's texts (questions, options, explanations) come from the questionnaire; these are
only the words around them.
"""

from __future__ import annotations

from functools import cache
from importlib import resources

import yaml

#: the language whose words every other language falls back to
FALLBACK = "en"


@cache
def _table() -> dict[str, dict[str, str]]:
    text = resources.files("kiosk.widgets").joinpath("ui_text.yaml").read_text(encoding="utf-8")
    return yaml.safe_load(text)


def ui_text(language: str, key: str, default: str | None = None, **values: object) -> str:
    """The words for ``key`` in ``language`` (English if missing), with ``values`` filled in.

    A key no language has gives ``default``; without one it is a KeyError (a typo in a screen).
    """
    table = _table()
    words = table.get(language, {}).get(key) or table[FALLBACK].get(key, default)
    if words is None:
        raise KeyError(f"no screen text {key!r}")
    return words.format(**values) if values else words
