"""Vosk (Kaldi) with a model directory and a JSON phrase-list grammar per question.

Confidence is the lowest word confidence Vosk reports, 0 with any "[unk]": Vosk's own word
confidences tell confusable words apart, so none of PocketSphinx's extra checks is needed.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Hashable, Sequence
from pathlib import Path
from typing import Any

from kiosk.speech.asr.base import AsrUnavailable, Recognition
from kiosk.speech.audio import SAMPLE_RATE
from kiosk.speech.grammar import Grammar, build_grammar, final_phrases, to_vosk


class VoskRecogniser:
    """Vosk (Kaldi) with a model directory and a JSON phrase-list grammar per question."""

    name = "vosk"
    #: why a better recogniser is not used ("" when none would be)
    fallback = ""

    def __init__(self, model_path: str | Path, language: str) -> None:
        try:
            import vosk
        except ImportError as exc:
            raise AsrUnavailable(f"vosk is not installed ({exc})") from None
        vosk.SetLogLevel(-1)
        path = Path(model_path)
        if not path.is_dir():
            raise AsrUnavailable(f"vosk model {path} does not exist")
        try:
            self._model = vosk.Model(str(path))
        except Exception as exc:  # vosk raises a bare Exception for a model it cannot load
            raise AsrUnavailable(f"vosk model {path} cannot be loaded ({exc})") from None
        self._vosk = vosk
        self.language = language
        self.model_path = path
        self._recogniser: Any = None  # a vosk.KaldiRecognizer once a grammar is set
        self._grammar: Grammar | None = None
        #: Vosk's JSON results for the segments of the current utterance
        self._segments: list[str] = []
        #: phrases that are a whole answer once heard (partial results say so)
        self._final: frozenset[str] = frozenset()

    def set_grammar(
        self,
        phrases: Sequence[str],
        meaning: Callable[[str], Hashable] | None = None,
        lead_ins: Sequence[str] = (),
        fillers: Sequence[str] = (),
        taken_as_heard: bool = False,
    ) -> Grammar:
        """Make a recogniser limited to the phrases the model knows (plus "[unk]").

        ``meaning`` is not needed: Vosk's own word confidences tell confusable words apart.
        ``taken_as_heard`` changes nothing: Vosk hears each utterance one way.
        """
        grammar = build_grammar(
            phrases, lambda w: self._model.vosk_model_find_word(w) >= 0, self.name, lead_ins, fillers, meaning
        )
        if not grammar.phrases:
            raise ValueError("a grammar needs at least one phrase the recogniser knows")
        self._recogniser = self._vosk.KaldiRecognizer(self._model, SAMPLE_RATE, to_vosk(grammar))
        self._recogniser.SetWords(True)
        self._grammar = grammar
        self._final = final_phrases(grammar.phrases, meaning or (lambda p: p))
        self.reset()
        return grammar

    def reset(self) -> None:
        """Drop any utterance in progress."""
        if self._recogniser is not None:
            self._recogniser.Reset()
        self._segments = []

    def accept(self, pcm: bytes) -> Recognition | None:
        """Decode more audio; Vosk may close a segment at its own pause detection. The partial
        result is the text of the whole utterance so far."""
        if self._recogniser is None:
            raise RuntimeError("set_grammar must be called before recognising")
        if self._recogniser.AcceptWaveform(pcm):
            self._segments.append(self._recogniser.Result())
            partial = ""
        else:
            partial = json.loads(self._recogniser.PartialResult()).get("partial", "")
        text = " ".join([*(json.loads(s).get("text", "") for s in self._segments), partial]).split()
        heard = " ".join(text)
        complete = self._grammar is not None and self._grammar.core(heard) in self._final
        return Recognition(heard, 0.0, final=False, complete=complete) if heard else None

    def finish(self) -> Recognition:
        """End the utterance and combine its segments (see :func:`vosk_recognition`)."""
        if self._recogniser is None:
            return Recognition("", 0.0)
        segments = [*self._segments, self._recogniser.FinalResult()]
        self._segments = []
        result = vosk_recognition(segments)
        if self._grammar is not None and self._grammar.core(result.text) not in self._grammar.phrases:
            # Vosk's grammar lets phrases follow one another, and a model without "[unk]" (the
            # Korean one) forces any sentence into a run of them ("셋 셋 혼자", each word 0.65
            # sure): only one phrase, maybe after a lead-in, is something a patient answered
            return Recognition(result.text, 0.0)
        return result


def vosk_recognition(results: Sequence[str]) -> Recognition:
    """One utterance from Vosk's JSON results (``{"text": ..., "result": [{"word", "conf"}...]}``).

    The confidence is the lowest word confidence; any "[unk]" makes it 0, because the unknown
    word may have been "not" in "not independent".
    """
    texts: list[str] = []
    confidences: list[float] = []
    for raw in results:
        result = json.loads(raw)
        if result.get("text"):
            texts.append(result["text"])
        confidences += [float(w.get("conf", 0.0)) for w in result.get("result", [])]
    text = " ".join(texts).strip()
    if not text or "[unk]" in text.split() or not confidences:
        return Recognition(text, 0.0)
    return Recognition(text, min(confidences))
