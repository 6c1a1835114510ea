"""What every recogniser is: the :class:`Recogniser` port, its :class:`Recognition` result, and
the one error that turns voice in off (:class:`AsrUnavailable`)."""

from __future__ import annotations

from collections.abc import Callable, Hashable, Sequence
from typing import Protocol

from basis import record
from basis.errors import KioskError
from kiosk.speech.grammar import Grammar


class AsrUnavailable(KioskError, RuntimeError):
    """Voice in cannot work for this language here; the message is one sentence for the UI."""


class NoModelForLanguage(AsrUnavailable):
    """No speech model for the language (Spanish or French without a Vosk model): the one
    reason a patient can be told, in their language (screen text ``voice_no_model``)."""

    reason_key = "voice_no_model"


@record
class Recognition:
    """What a recogniser made of (part of) an utterance."""

    text: str
    #: in [0, 1]; 0 when nothing was recognised
    confidence: float
    #: False for a partial result while the patient is still speaking
    final: bool = True
    #: for a partial result: it already is a whole answer (one of the grammar's
    #: :func:`~kiosk.speech.grammar.final_phrases`), so the endpointer need not wait long
    complete: bool = False
    #: pocketsphinx: how much worse the phrase fits the audio than free phones do (cost per
    #: voiced frame); the acoustic part of the confidence, kept for bench/asr.py's calibration
    fit: float | None = None
    #: the phrase holds a word the model cannot tell from one of another answer ("first" /
    #: "third"): never taken without asking the patient back (see :class:`PocketSphinxRecogniser`)
    confusable: bool = False


class Recogniser(Protocol):
    """One recogniser, one utterance at a time, under the current question's grammar."""

    #: "vosk" or "pocketsphinx", shown as the voice channel's source
    name: str
    language: str

    def set_grammar(
        self,
        phrases: Sequence[str],
        meaning: Callable[[str], Hashable] | None = None,
        lead_ins: Sequence[str] = (),
        fillers: Sequence[str] = (),
        taken_as_heard: bool = False,
    ) -> Grammar:
        """Listen only for these phrases (each maybe after one lead-in, or one of the fillers)
        from the next utterance on; returns what was kept.

        ``meaning(phrase)`` says what a phrase selects (an option number, a command): phrases
        with the same meaning are not rivals of one another (see :class:`PocketSphinxRecogniser`).
        Without it every phrase means only itself. ``taken_as_heard``: an option heard under
        this grammar is acted on without being asked back (a confirmation's yes or no), so a
        recogniser that can hear it two ways should make sure both agree.
        """

    def reset(self) -> None:
        """Forget the current utterance and get ready for a new one."""

    def accept(self, pcm: bytes) -> Recognition | None:
        """Take more audio of the current utterance; may return a partial result."""

    def finish(self) -> Recognition:
        """End the current utterance and return the final result."""
