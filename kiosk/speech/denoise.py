"""Steady-noise reduction for one utterance before the recogniser scores it (spectral subtraction).

A fan, an air conditioner or a corridor's hum fills the spectrum between the words; pocketsphinx's
model was trained on clean speech, so it heard the right phrase but scored it too low to take.
The noise's spectrum is estimated from the utterance's own quietest frames (the endpointer keeps
a moment of room before and after the words), and subtracted from every frame, never below
:data:`FLOOR` of the frame's own magnitude (deeper cuts leave "musical noise" the model hears as
phones).

Three cases are left alone: background talk, which comes and goes (:data:`STEADY_SPREAD_DB`); a
quiet room (noise below :data:`QUIET_ROOM_DBFS`), where the quietest frames hold the ends of the
words; and an utterance with nothing above the noise, where subtracting the noise from itself
leaves warbling tones the recogniser takes for words. Measured: docs/speech-tuning.md.
"""

from __future__ import annotations

import numpy as np

#: analysis frame and hop, in samples at 16 kHz (32 ms and 8 ms)
FRAME, HOP = 512, 128
#: the share of the utterance's frames, quietest first, that estimate the noise (in a quiet room
#: it takes in the ends of the words, which is one reason quiet rooms are left alone)
QUIET_SHARE = 0.2
#: how much of the noise estimate is subtracted (1: exactly the estimate)
OVER_SUBTRACTION = 1.5
#: the least of each frequency's magnitude that is kept
FLOOR = 0.1
#: steady noise: the quietest 10 % of the frames lie within this many dB of the quietest 2 %
#: (white noise: 0.2-0.4 dB; background talk: 3-4 dB)
STEADY_SPREAD_DB = 1.5
#: below this noise level (dBFS) the room is quiet and nothing is done
QUIET_ROOM_DBFS = -55.0
#: the loudest tenth of the frames must stand this far above the noise, or nothing is done
SPEECH_ABOVE_NOISE_DB = 6.0


def reduce_steady_noise(pcm: bytes) -> bytes:
    """16 kHz mono int16 PCM with its steady background noise subtracted (same length).

    Shorter than a few frames, the utterance is returned as it is.
    """
    samples = np.frombuffer(pcm, dtype="<i2").astype(np.float64)
    if len(samples) < FRAME * 4:
        return pcm
    window = np.sqrt(np.hanning(FRAME + 1)[:-1])  # squared, the windows add up to a constant
    count = 1 + (len(samples) - FRAME) // HOP
    index = np.arange(FRAME)[None, :] + HOP * np.arange(count)[:, None]
    spectra = np.fft.rfft(samples[index] * window, axis=1)
    power = np.abs(spectra) ** 2
    energy = power.sum(axis=1)
    quietest, quiet = np.quantile(energy, [0.02, 0.1])  # the room between the words
    if quiet > quietest * 10 ** (STEADY_SPREAD_DB / 10):
        # the room's sound comes and goes (people talking): no one spectrum to take out, and
        # subtracting an average of it cost right answers in background talk
        return pcm
    noise = power[energy <= np.quantile(energy, QUIET_SHARE)].mean(axis=0)
    noise_energy = float(noise.sum())
    squared = window**2
    # the noise's level in dBFS (Parseval: a frame's spectral power over FRAME times the
    # window's power is its mean square)
    level = 10 * np.log10(max(noise_energy / (FRAME * float(squared.sum())), 1e-12) / 32768**2)
    if level < QUIET_ROOM_DBFS:
        return pcm  # a quiet room: taking its hiss out only cost confidence
    if np.quantile(energy, 0.9) < noise_energy * 10 ** (SPEECH_ABOVE_NOISE_DB / 10):
        # nothing stands out of the noise: no words to clean, and subtracting the noise from
        # itself leaves warbling tones that the recogniser took for "needs help"
        return pcm
    gain = np.sqrt(np.maximum(1.0 - OVER_SUBTRACTION * noise / np.maximum(power, 1e-12), FLOOR**2))
    frames = np.fft.irfft(spectra * gain, n=FRAME, axis=1) * window
    out = np.zeros(len(samples))
    weight = np.zeros(len(samples))
    for i in range(count):  # overlap-add (about 1250 frames for a 10 s utterance)
        out[i * HOP : i * HOP + FRAME] += frames[i]
        weight[i * HOP : i * HOP + FRAME] += squared
    # the few samples at the end that no whole frame covers are kept as they were
    out = np.where(weight > 1e-3, out / np.maximum(weight, 1e-3), samples)
    return np.clip(np.round(out), -32768, 32767).astype("<i2").tobytes()
