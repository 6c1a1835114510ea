"""Frame-level views of one utterance for PocketSphinx's scoring: which 10 ms frames are voiced,
which stand out of the room, the talk around the patient's words turned down, a fixed quiet tail.

Pure functions of 16 kHz mono int16 PCM, so each is tested on its own (tests/kiosk/speech/test_rooms.py).
Why each constant has its value: docs/speech-tuning.md; measured: bench/RESULTS.md.
"""

from __future__ import annotations

import numpy as np

from kiosk.speech.audio import SAMPLE_RATE, frame_powers

#: bytes per 10 ms frame, pocketsphinx's frame rate
FRAME_BYTES = 2 * SAMPLE_RATE // 100
#: 10 ms frames of quiet after the last voiced one that the final decode scores: the long
#: hangover's worth (see :func:`fixed_tail`)
PS_TRAILING_FRAMES = 50
#: the utterance's first 10 ms frames, the endpointer's pre-roll, are the room it was said in
#: (:func:`above_room`) ...
PS_ROOM_FRAMES = 20
#: ... and where people talk nearby, coverage counts only the frames this far above the loudest
#: tenth of it: their talk around a short "two" or "no" is not the patient's
PS_ABOVE_ROOM_DB = 2.0
#: only a start at least this far below the loudest frame is taken for room
PS_ROOM_BELOW_SPEECH_DB = 6.0
#: a room whose sound even at the quietest tenth of an utterance (the pre-roll and the hangover
#: hold at least half a second of it) is this loud is one where people talk nearby: the level
#: the endpointer takes for speech at all (:attr:`kiosk.speech.audio.EndpointerSettings.min_speech_db`).
#: A microphone's hiss and a quiet ward are far below it; a fan's noise is subtracted instead
#: (:mod:`kiosk.speech.denoise`)
PS_TALKING_ROOM_DB = -55.0
#: in such a room the talk around the patient's words is turned down by this much before the
#: utterance is scored (:func:`gate_talk`) ...
PS_TALK_GATE_DB = -30.0
#: ... keeping this many 10 ms frames on either side of the patient's words, for the quiet
#: edges of a word ("yes" ends in a soft "s")
PS_TALK_GATE_KEEP_FRAMES = 10


def fixed_tail(pcm: bytes, voiced: np.ndarray) -> tuple[bytes, np.ndarray]:
    """The utterance with exactly :data:`PS_TRAILING_FRAMES` of quiet after its last voiced frame.

    The cost per voiced frame also counts the quiet after the speech, so an utterance the
    endpointer closed early (a whole answer after a short pause) would score better than the
    same one closed after the long hangover. Cutting a longer tail, and lengthening a shorter
    one by repeating the quiet actually heard (the room's own noise), scores both alike.
    """
    step = FRAME_BYTES
    end = (int(np.flatnonzero(voiced)[-1]) + 1) * step
    tail = pcm[end : end + PS_TRAILING_FRAMES * step] or b"\0" * step
    tail = (tail * (PS_TRAILING_FRAMES * step // len(tail) + 1))[: PS_TRAILING_FRAMES * step]
    out = pcm[:end] + tail
    return out, np.concatenate([voiced[: end // step], np.zeros(PS_TRAILING_FRAMES, dtype=bool)])


def above_room(pcm: bytes, frames: int) -> np.ndarray:
    """Per 10 ms frame (the first ``frames``), whether it stands :data:`PS_ABOVE_ROOM_DB` above
    the room heard in the utterance's first :data:`PS_ROOM_FRAMES` (the pre-roll the endpointer
    keeps from before the speech started): in a quiet room every frame of the words does; with
    people talking nearby their words in the pre-roll and the hangover do not.

    All True when the start is not clearly quieter than the loudest frame (no pre-roll of room
    to go by, e.g. audio handed over without one).
    """
    level = frame_levels(pcm)[:frames]
    out = np.ones(frames, dtype=bool)
    out[: len(level)] = stands_out(level)
    return out


def stands_out(level: np.ndarray) -> np.ndarray:
    """:func:`above_room` for frame levels (dBFS) already measured."""
    if len(level) <= PS_ROOM_FRAMES:
        return np.ones(len(level), dtype=bool)
    room = float(np.percentile(level[:PS_ROOM_FRAMES], 90))
    if room > level.max() - PS_ROOM_BELOW_SPEECH_DB:
        return np.ones(len(level), dtype=bool)
    return level >= room + PS_ABOVE_ROOM_DB


def gate_talk(pcm: bytes) -> bytes:
    """The utterance with other people's talk turned down by :data:`PS_TALK_GATE_DB` wherever
    it does not stand out of the room heard in the pre-roll (:func:`above_room`), keeping
    :data:`PS_TALK_GATE_KEEP_FRAMES` around the patient's words; unchanged where the room
    is quieter than :data:`PS_TALKING_ROOM_DB` (a quiet room).

    The pre-roll, the hangover and the fixed tail (:func:`fixed_tail`) of an answer given in
    background talk are talk: the grammar's longer phrases absorbed it, so a short "yes" or
    "no" was heard as a longer phrase, and the words that fitted the talk best became the
    confidence's yardstick. Turned down, the talk around the words is scored as the quiet it
    stands for (measured: bench/RESULTS.md; tuning: docs/speech-tuning.md).
    """
    level = frame_levels(pcm)
    if len(level) <= PS_ROOM_FRAMES or np.percentile(level, 10) < PS_TALKING_ROOM_DB:
        return pcm
    words = stands_out(level)
    if words.all() or not words.any():
        return pcm  # no room to go by, or nothing stands out of it: nothing to tell apart
    keep = words.copy()
    for shift in range(1, PS_TALK_GATE_KEEP_FRAMES + 1):
        keep[shift:] |= words[:-shift]
        keep[:-shift] |= words[shift:]
    gain = np.repeat(np.where(keep, 1.0, 10 ** (PS_TALK_GATE_DB / 20)), FRAME_BYTES // 2)
    # a 5 ms ramp at each edge, so the gate does not click (a click is a consonant to the model)
    gain = np.convolve(gain, np.ones(80) / 80, mode="same")
    samples = np.frombuffer(pcm, dtype="<i2").astype(np.float64)
    samples[: len(gain)] *= gain
    return np.clip(np.round(samples), -32768, 32767).astype("<i2").tobytes()


def frame_levels(pcm: bytes) -> np.ndarray:
    """Level (dBFS) of each whole 10 ms frame."""
    power = frame_powers(np.frombuffer(pcm, dtype="<i2")) / 32768.0**2
    return 10 * np.log10(np.maximum(power, 1e-10))


def voiced_frames(pcm: bytes, above_floor_db: float | None = None) -> np.ndarray:
    """Per 10 ms frame (pocketsphinx's frame rate), whether it holds speech rather than silence.

    Voiced means within 30 dB of the utterance's loudest frame and above -55 dBFS, and, given
    ``above_floor_db``, that far above the utterance's quietest tenth (what is left of a noise
    that was subtracted: see :meth:`kiosk.speech.asr.sphinx.PocketSphinxRecogniser.finish`).
    """
    level = frame_levels(pcm)
    if len(level) == 0:
        return np.zeros(0, dtype=bool)
    voiced = (level >= level.max() - 30) & (level >= -55)
    if above_floor_db is not None:
        voiced &= level >= np.percentile(level, 10) + above_floor_db
    return voiced
