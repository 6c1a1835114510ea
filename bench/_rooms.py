"""Simulated rooms for measuring and testing voice in: the audio a kiosk's microphone would
record when a patient answers in a noisy ward, made from clean speech with numpy.

There is no microphone here, so ``bench/asr.py`` and the speech tests (its only users: the kiosk
itself never simulates a room) make the conditions the
kiosk meets -- a fan (steady noise), people talking nearby (babble), a reverberant room, a
telephone-band microphone, a quiet speaker -- from espeak-ng speech, deterministically (every
random draw comes from a seeded generator). All audio is 16 kHz mono int16, as the pipeline
takes it (:data:`kiosk.speech.audio.SAMPLE_RATE`).

SNR is measured against the speech's *active* level (frames within 30 dB of its loudest, as
ITU-T P.56 does more carefully), so "10 dB" means the same for a short "yes" as for a long
sentence.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from kiosk.speech.audio import SAMPLE_RATE, frame_powers


def active_power(speech: np.ndarray) -> float:
    """Mean power of the speech's active 10 ms frames (within 30 dB of the loudest)."""
    power = frame_powers(speech)
    if len(power) == 0:
        return 0.0
    active = power[power >= power.max() * 1e-3]
    return float(active.mean()) if len(active) else 0.0


def _to_int16(x: np.ndarray) -> np.ndarray:
    return np.clip(np.round(x), -32768, 32767).astype(np.int16)


def scale_db(samples: np.ndarray, db: float) -> np.ndarray:
    """The same audio ``db`` louder (negative: quieter), clipped to int16."""
    return _to_int16(samples.astype(np.float64) * 10 ** (db / 20))


def white_noise(seconds: float, rng: np.random.Generator) -> np.ndarray:
    """Unit-power Gaussian white noise (float), like a fan or an air vent close by."""
    return rng.standard_normal(int(seconds * SAMPLE_RATE))


def babble(talkers: Sequence[np.ndarray], seconds: float, rng: np.random.Generator) -> np.ndarray:
    """Unit-power background talk: each talker's recordings looped from a random point, summed.

    ``talkers`` are other voices saying other things; four or more sound like a busy ward,
    one or two like a conversation nearby.
    """
    n = int(seconds * SAMPLE_RATE)
    mix = np.zeros(n)
    for speech in talkers:
        x = speech.astype(np.float64)
        x = x / np.sqrt(max(active_power(speech), 1e-9))
        start = int(rng.integers(0, len(x)))
        mix += np.resize(np.roll(x, -start), n)
    power = float((mix**2).mean())
    return mix / np.sqrt(power) if power > 0 else mix


def mix_at_snr(speech: np.ndarray, noise: np.ndarray, snr_db: float, offset: int = 0) -> np.ndarray:
    """``noise`` with ``speech`` added at sample ``offset``, the noise scaled so that the
    speech's active level is ``snr_db`` above it. ``noise`` (unit power) sets the length."""
    out = noise * np.sqrt(active_power(speech) / 10 ** (snr_db / 10))
    end = min(len(out), offset + len(speech))
    out[offset:end] += speech[: end - offset].astype(np.float64)
    return _to_int16(out)


def reverberate(speech: np.ndarray, rt60: float, rng: np.random.Generator) -> np.ndarray:
    """The speech in a room with reverberation time ``rt60`` (s): convolved with a synthetic
    impulse response (direct sound, then exponentially decaying noise), at the same active level."""
    n = int(rt60 * SAMPLE_RATE)
    t = np.arange(n) / SAMPLE_RATE
    response = rng.standard_normal(n) * np.exp(-6.9 * t / rt60) * 0.3
    response[0] = 1.0
    x = speech.astype(np.float64)
    wet = np.fft.irfft(np.fft.rfft(x, len(x) + n) * np.fft.rfft(response, len(x) + n), len(x) + n)
    wet *= np.sqrt(active_power(speech) / max(active_power(_to_int16(wet)), 1e-9))
    return _to_int16(wet)


def telephone_band(speech: np.ndarray, low: float = 300.0, high: float = 3400.0) -> np.ndarray:
    """The speech through a telephone-quality microphone: only ``low``-``high`` Hz kept."""
    if len(speech) == 0:
        return speech.copy()
    spectrum = np.fft.rfft(speech.astype(np.float64))
    freqs = np.fft.rfftfreq(len(speech), 1 / SAMPLE_RATE)
    spectrum[(freqs < low) | (freqs > high)] = 0
    return _to_int16(np.fft.irfft(spectrum, len(speech)))


def cough(rng: np.random.Generator, level_db: float = -20.0) -> np.ndarray:
    """A cough-like burst: 250-400 ms of band-limited noise with a sharp attack, at ``level_db``
    dBFS RMS. Not speech, and never an answer."""
    n = int(rng.uniform(0.25, 0.4) * SAMPLE_RATE)
    t = np.arange(n) / SAMPLE_RATE
    noise = rng.standard_normal(n)
    spectrum = np.fft.rfft(noise)
    freqs = np.fft.rfftfreq(n, 1 / SAMPLE_RATE)
    spectrum[(freqs < 200) | (freqs > 3000)] = 0
    burst = np.fft.irfft(spectrum, n) * np.minimum(1.0, t / 0.01) * np.exp(-t / 0.12)
    burst *= 32768 * 10 ** (level_db / 20) / max(np.sqrt((burst**2).mean()), 1e-9)
    return _to_int16(burst)
