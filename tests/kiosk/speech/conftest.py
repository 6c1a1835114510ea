"""Fixtures shared by the speech tests."""

from __future__ import annotations

from pathlib import Path

import pytest

from kiosk.speech.tts import Synthesiser


@pytest.fixture(scope="session")
def spoken(tmp_path_factory, espeak_ng):
    """say(text, language) → a WAV of the kiosk's own espeak-ng synthesiser saying it at its
    default rate (cached for the session): the answers a patient speaks in these tests."""
    folder = tmp_path_factory.mktemp("spoken")
    synthesiser = Synthesiser()

    def say(text: str, language: str = "en") -> Path:
        path = folder / f"{language}-{text.replace(' ', '_')}.wav"
        if not path.exists():
            synthesiser.synthesise(text, language, path)
        return path

    return say
