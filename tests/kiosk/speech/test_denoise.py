"""Steady-noise reduction (kiosk.speech.denoise) on real espeak-ng speech in white noise, and
what it does for the real pocketsphinx recogniser."""

from __future__ import annotations

import numpy as np
import pytest

from bench import _rooms as rooms
from kiosk.speech.asr import PocketSphinxRecogniser
from kiosk.speech.audio import SAMPLE_RATE
from kiosk.speech.denoise import reduce_steady_noise

from .test_rooms import Ear, _in_noise, voice_of  # noqa: F401  (voice_of is a fixture)


def _db(samples: np.ndarray) -> float:
    return 10 * np.log10(max(float((samples.astype(np.float64) ** 2).mean()), 1e-9))


def _pcm(samples: np.ndarray) -> np.ndarray:
    return np.frombuffer(reduce_steady_noise(samples.astype("<i2").tobytes()), dtype="<i2")


@pytest.mark.slow  # real audio (espeak-ng)
def test_a_fans_noise_is_taken_out_and_the_words_are_kept(voice_of):
    speech = voice_of("I need a lot of help", "en-us+m3", 130)
    rng = np.random.default_rng(7)
    noisy = _in_noise(speech, rooms.white_noise(len(speech) / SAMPLE_RATE + 3.0, rng), snr_db=10)
    clean = _in_noise(speech, None)[: len(noisy)]
    out = _pcm(noisy)
    assert len(out) == len(noisy)
    before, words = (
        slice(0, int(1.2 * SAMPLE_RATE)),
        slice(int(1.5 * SAMPLE_RATE), int(1.5 * SAMPLE_RATE) + len(speech)),
    )
    # spectral subtraction with a floor takes a few dB, not all of it (measured: 4-5 dB here)
    assert _db(out[before]) < _db(noisy[before]) - 3, "the noise between the words is at least halved"
    assert abs(_db(out[words]) - _db(clean[words])) < 3, "the words keep their level"
    # and the result is nearer the clean words than the noisy input was
    residual = lambda x: _db(x[words].astype(np.float64) - clean[words])  # noqa: E731
    assert residual(out) < residual(noisy) - 3


@pytest.mark.slow  # real audio (espeak-ng)
def test_a_quiet_room_is_left_as_it_was(voice_of):
    speech = voice_of("independent", "en+f2", 170)
    quiet = _in_noise(speech, None)
    quiet = (quiet + np.random.default_rng(1).normal(0, 32768 * 10 ** (-75 / 20), len(quiet))).astype(np.int16)
    out = _pcm(quiet)
    difference = _db(out.astype(np.float64) - quiet)
    assert difference < _db(quiet) - 30, "nothing audible changes in a quiet room"


def test_too_short_to_estimate_is_returned_unchanged():
    pcm = np.arange(1000, dtype="<i2").tobytes()
    assert reduce_steady_noise(pcm) == pcm
    assert reduce_steady_noise(b"") == b""


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("text,option", [("independent", 3), ("needs help", 2), ("two", 2)])
def test_answers_in_a_fans_noise_are_heard(voice_of, text, option):
    """The kiosk's own voice at SNR 10 dB of white noise: each answer is heard as itself and sure
    enough to be asked back ("I heard: ... Is that right?"). ("number one" is not: the model's
    silence fits espeak-ng's "number" better than the word, see kiosk.speech.asr.)"""
    ear = Ear().question("feeding")
    rng = np.random.default_rng(10)
    ear.hear(_in_noise(np.zeros(0), rooms.white_noise(2, rng), 10))  # the fan was on before
    speech = voice_of(text, "en-us", 160)
    got = ear.hear(_in_noise(speech, rooms.white_noise(len(speech) / SAMPLE_RATE + 3.5, rng), 10))
    assert got is not None and got.option == option and got.needs_confirmation


def test_noise_alone_is_never_cleaned_into_an_answer():
    """Noise alone is never cleaned into an answer: subtracting white noise from itself left
    warbling tones that pocketsphinx took for "needs help" (4 of 5 seeds, confidence 0.84-0.95)
    until utterances with nothing above the noise were left alone."""
    for seed in range(5):
        recogniser = PocketSphinxRecogniser("en")
        recogniser.set_grammar(["independent", "unable", "needs help", "yes", "no"])
        noise = np.clip(rooms.white_noise(2.0, np.random.default_rng(seed)) * 3000, -32768, 32767).astype("<i2")
        assert reduce_steady_noise(noise.tobytes()) == noise.tobytes()
        recogniser.accept(noise.tobytes())
        assert recogniser.finish().confidence < 0.6, seed


@pytest.mark.slow  # real audio (espeak-ng)
def test_background_talk_is_left_as_it_is(voice_of):
    """People talking come and go: there is no one noise spectrum to take out (subtracting an
    average one cost right answers in bench/asr.py's babble)."""
    talkers = [
        voice_of(text, voice, 170)
        for text, voice in (
            ("could you bring the trolley round to bed twelve when you have a moment please", "en-gb+m1"),
            ("the pharmacy said the new tablets will be ready after the lunch round", "en-us+f1"),
            ("we went to the seaside last summer and the weather was lovely all week", "en+m6"),
        )
    ]
    speech = voice_of("I need a lot of help", "en-us+m3", 130)
    rng = np.random.default_rng(5)
    noisy = _in_noise(speech, rooms.babble(talkers, len(speech) / SAMPLE_RATE + 3.0, rng), snr_db=10)
    assert reduce_steady_noise(noisy.tobytes()) == noisy.tobytes()
