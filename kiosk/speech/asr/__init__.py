"""Speech recognisers behind one small interface: Vosk (primary) and PocketSphinx (fallback).

A :class:`Recogniser` takes one utterance at a time (16 kHz mono int16 PCM, see
:mod:`kiosk.speech.audio`) under a per-question grammar and returns its text with a confidence
in [0, 1], the one scale the matcher's thresholds are set on:

- :class:`VoskRecogniser` (:mod:`.kaldi`): a Kaldi model installed with `kiosk models install LANG`
  (or given by ``KIOSK_VOSK_MODEL``), grammar as a JSON phrase list with "[unk]".
- :class:`PocketSphinxRecogniser` (:mod:`.sphinx`, with :mod:`.levels`): the English model in the
  pocketsphinx wheel, grammar as JSGF; its confidence is the lowest of simple checks a clinician
  can follow (a whole phrase, coverage of the voiced audio, fit against free phone decoding).

:func:`open_recogniser` picks Vosk when a model for the language is installed, else
PocketSphinx for English, else raises :class:`AsrUnavailable` with the reason voice in is off.
Tuning history: docs/speech-tuning.md; measured: bench/RESULTS.md.
"""

from __future__ import annotations

from pathlib import Path

from kiosk.speech.asr.base import AsrUnavailable, NoModelForLanguage, Recogniser, Recognition
from kiosk.speech.asr.kaldi import VoskRecogniser, vosk_recognition
from kiosk.speech.asr.sphinx import PocketSphinxRecogniser, accent_variants

__all__ = [
    "AsrUnavailable",
    "NoModelForLanguage",
    "PocketSphinxRecogniser",
    "Recogniser",
    "Recognition",
    "VoskRecogniser",
    "accent_variants",
    "open_recogniser",
    "vosk_recognition",
]


def open_recogniser(language: str, model_path: str | Path | None = None) -> Recogniser:
    """The best recogniser for ``language`` on this machine.

    Vosk with the model ``model_path`` (a model or a folder of models, see
    :func:`kiosk.speech.models.find_model`) or an installed one;
    else PocketSphinx for English; else :class:`AsrUnavailable` saying why voice in is off.
    """
    from kiosk.speech.models import find_model

    path = find_model(language, model_path)
    if path is not None:
        return VoskRecogniser(path, language)
    return PocketSphinxRecogniser(language)
