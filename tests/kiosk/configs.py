"""The kiosk's configuration files as the tests write them, and the one message a bad one gives."""

from __future__ import annotations

from pathlib import Path

import pytest

from kiosk.config import ConfigError, load_config


def refusal(path: Path, text: str | None = None) -> str:
    """The message of the :class:`ConfigError` that loading ``path`` raises (``text`` written there
    first, when given), with no environment overrides."""
    if text is not None:
        path.write_text(text)
    with pytest.raises(ConfigError) as caught:
        load_config(path, environ={})
    return str(caught.value)
