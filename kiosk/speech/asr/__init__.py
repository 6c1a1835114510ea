"""Speech recognisers behind one small interface: Vosk (primary) and PocketSphinx (fallback).

A :class:`Recogniser` takes one utterance at a time (16 kHz mono int16 PCM, see
:mod:`kiosk.speech.audio`) under a per-question grammar and returns its text with a confidence
in [0, 1], the one scale the matcher's thresholds are set on:

- :class:`VoskRecogniser` (:mod:`.kaldi`): a Kaldi model installed with `kiosk models install LANG`
  (or given by ``KIOSK_VOSK_MODEL``), grammar as a JSON phrase list with "[unk]".
- :class:`PocketSphinxRecogniser` (:mod:`.sphinx`, with :mod:`.levels`): the English model in the
  pocketsphinx wheel, grammar as JSGF; its confidence is the lowest of simple checks a clinician
  can follow (a whole phrase, coverage of the voiced audio, fit against free phone decoding).

- :class:`WhisperRecogniser` (:mod:`.whisper`, models from :mod:`.whisper_files`): Whisper in
  CTranslate2 form decoding each whole utterance (tiny.en for English, base for Spanish, French
  and German), with PocketSphinx ending English turns.

:func:`open_recogniser` picks a Vosk model given explicitly, else Whisper where its packages are
installed, else an installed Vosk model, else PocketSphinx for English, else raises
:class:`AsrUnavailable` with the reason voice in is off. A recogniser that fell back says why in
``fallback`` (shown with the voice channel's status).
Tuning history: docs/speech-tuning.md; measured: bench/RESULTS.md.
"""

from __future__ import annotations

import logging
from pathlib import Path

from kiosk.speech.asr.base import AsrUnavailable, NoModelForLanguage, Recogniser, Recognition
from kiosk.speech.asr.kaldi import VoskRecogniser, vosk_recognition
from kiosk.speech.asr.sphinx import PocketSphinxRecogniser, accent_variants
from kiosk.speech.asr.whisper import WhisperRecogniser

log = logging.getLogger(__name__)

__all__ = [
    "AsrUnavailable",
    "NoModelForLanguage",
    "PocketSphinxRecogniser",
    "Recogniser",
    "Recognition",
    "VoskRecogniser",
    "WhisperRecogniser",
    "accent_variants",
    "open_recogniser",
    "open_whisper",
    "vosk_recognition",
]


def open_recogniser(language: str, model_path: str | Path | None = None) -> Recogniser:
    """The best recogniser for ``language`` on this machine.

    Vosk with the model ``model_path`` (a model or a folder of models, see
    :func:`kiosk.speech.models.find_model`) when one is given; else Whisper; else an installed
    Vosk model; else PocketSphinx for English; else :class:`AsrUnavailable` saying why voice in
    is off (Whisper's reason included). Imports nothing heavy before it is called (the loader
    thread calls it after the first frame).
    """
    from kiosk.speech.models import find_model

    if model_path is not None and (path := find_model(language, model_path)) is not None:
        return VoskRecogniser(path, language)
    try:
        return open_whisper(language)
    except AsrUnavailable as exc:
        why = str(exc)
    log.info("voice: Whisper is not used for %r: %s", language, why)
    path = find_model(language)
    if path is not None:
        vosk = VoskRecogniser(path, language)
        vosk.fallback = f"Whisper unavailable: {why}"
        return vosk
    try:
        sphinx = PocketSphinxRecogniser(language)
    except NoModelForLanguage as exc:
        raise NoModelForLanguage(f"{exc} (Whisper: {why})") from None
    sphinx.fallback = f"Whisper unavailable: {why}"
    return sphinx


def open_whisper(language: str, *, prompt: bool = True) -> Recogniser:
    """Whisper for ``language``, with PocketSphinx ending English turns; :class:`AsrUnavailable`
    when a package is missing or a model file is damaged."""
    detector = PocketSphinxRecogniser("en") if language == "en" else None
    return WhisperRecogniser(language, detector, prompt=prompt)
