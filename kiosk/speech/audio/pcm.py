"""16 kHz mono int16 PCM, the one format every recogniser takes: WAV files in, frame levels, and
feeding samples to a pipeline the way a microphone would (the tests and bench/asr.py do so)."""

from __future__ import annotations

import math
import wave
from pathlib import Path
from typing import Protocol

import numpy as np

#: what every recogniser in the kiosk takes: 16 kHz, mono, signed 16-bit little-endian
SAMPLE_RATE = 16_000
#: the endpointer's analysis frame: 30 ms, a usual speech frame length
FRAME_SAMPLES = 480


def resample(samples: np.ndarray, rate: int, target: int = SAMPLE_RATE) -> np.ndarray:
    """Resample mono int16 audio to ``target`` Hz (windowed-sinc low-pass, then interpolation).

    Good enough for speech recognition, which ignores everything above ~7 kHz anyway; it keeps
    the kiosk free of a SciPy dependency.
    """
    if rate == target:
        return samples.astype(np.int16, copy=False)
    x = samples.astype(np.float64)
    if target < rate:  # remove what would alias above the new Nyquist frequency
        cutoff = 0.95 * (target / 2) / rate
        taps = np.arange(-32, 33)
        kernel = np.sinc(2 * cutoff * taps) * np.hamming(len(taps))
        x = np.convolve(x, kernel / kernel.sum(), mode="same")
    n = int(len(x) * target / rate)
    y = np.interp(np.arange(n) * (rate / target), np.arange(len(x)), x)
    return np.clip(np.round(y), -32768, 32767).astype(np.int16)


def read_wav(path: str | Path) -> np.ndarray:
    """A 16-bit PCM WAV file as 16 kHz mono int16 samples (channels averaged, resampled).

    Raises ``ValueError`` naming the file for anything else (8-bit, float, not a WAV).
    """
    try:
        with wave.open(str(path), "rb") as wav:
            if wav.getsampwidth() != 2:
                raise ValueError(f"{path}: {8 * wav.getsampwidth()}-bit WAV, expected 16-bit PCM")
            channels, rate = wav.getnchannels(), wav.getframerate()
            data = np.frombuffer(wav.readframes(wav.getnframes()), dtype="<i2")
    except (wave.Error, EOFError) as exc:
        raise ValueError(f"{path}: not a PCM WAV file ({exc})") from None
    if channels > 1:
        data = data.reshape(-1, channels).mean(axis=1).astype(np.int16)
    return resample(data, rate)


def frame_powers(samples: np.ndarray) -> np.ndarray:
    """Mean power of each whole 10 ms frame of int16 samples (int16 units squared): the frame
    rate of the recognisers' features and of the simulated rooms' levels (``bench/_rooms.py``)."""
    x = samples.astype(np.float64)
    step = SAMPLE_RATE // 100
    return (x[: len(x) - len(x) % step].reshape(-1, step) ** 2).mean(axis=1)


def frame_level_db(frame: np.ndarray) -> float:
    """RMS level of int16 samples in dB relative to full scale (-100 for digital silence)."""
    if len(frame) == 0:
        return -100.0
    rms = math.sqrt(float(np.mean(frame.astype(np.float64) ** 2))) / 32768.0
    return max(-100.0, 20 * math.log10(rms)) if rms > 0 else -100.0


class PcmConsumer(Protocol):
    """Anything that takes 16 kHz mono int16 audio: a pipeline, a voice channel."""

    def feed(self, pcm: bytes) -> None:
        """Take more audio."""


def feed_wav(path: str | Path, pipeline: PcmConsumer, chunk_ms: int = 100) -> float:
    """Play a WAV file into ``pipeline`` as a microphone would deliver it; returns its length (s).

    The file is followed by a second of silence, as a room falls quiet after an answer, so the
    endpointer can close the last utterance.
    """
    samples = read_wav(path)
    feed_samples(np.concatenate([samples, np.zeros(SAMPLE_RATE, dtype=np.int16)]), pipeline, chunk_ms)
    return len(samples) / SAMPLE_RATE


def feed_samples(samples: np.ndarray, pipeline: PcmConsumer, chunk_ms: int = 100) -> None:
    """Feed 16 kHz mono int16 samples into ``pipeline`` in microphone-sized chunks."""
    pcm = samples.astype("<i2", copy=False).tobytes()
    step = 2 * SAMPLE_RATE * chunk_ms // 1000
    for offset in range(0, len(pcm), step):
        pipeline.feed(pcm[offset : offset + step])
