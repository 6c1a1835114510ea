"""Audio in: device listing, WAV reading, the endpointer and the pipeline on real signals."""

from __future__ import annotations

import wave

import numpy as np
import pytest

from kiosk.speech import audio
from kiosk.speech.asr import Recognition
from kiosk.speech.audio import (
    FRAME_SAMPLES,
    SAMPLE_RATE,
    AudioUnavailable,
    Endpointer,
    UtterancePipeline,
    describe_input,
    feed_wav,
    read_wav,
)


def _tone(seconds: float, db: float, rate: int = SAMPLE_RATE) -> np.ndarray:
    t = np.arange(int(seconds * rate)) / rate
    amp = 32768 * 10 ** (db / 20) * np.sqrt(2)
    return (amp * np.sin(2 * np.pi * 220 * t)).astype(np.int16)


def _silence(seconds: float) -> np.ndarray:
    return np.zeros(int(seconds * SAMPLE_RATE), dtype=np.int16)


class _Recorder:
    """A recogniser stand-in that keeps what it heard, to check what the pipeline passes on."""

    def __init__(self) -> None:
        self.heard = b""
        self.resets = 0

    def reset(self) -> None:
        self.heard = b""
        self.resets += 1

    def accept(self, pcm: bytes) -> None:
        self.heard += pcm

    def finish(self) -> int:
        return len(self.heard) // 2


def test_describe_input_reports_default_and_refusal():
    def check(index: int) -> None:
        if index == 3:
            raise ValueError("Invalid sample rate")

    ok = describe_input({"index": 1, "name": "USB mic", "default_samplerate": 48000.0}, 1, check)
    bad = describe_input({"index": 3, "name": "HDMI", "default_samplerate": 44100.0}, 1, check)
    assert (ok.usable, ok.default, ok.sample_rate, ok.reason) == (True, True, 48000.0, "")
    assert (bad.usable, bad.default) == (False, False)
    assert "Invalid sample rate" in bad.reason


def test_list_input_devices_on_this_machine():
    devices = audio.list_input_devices()
    assert all(isinstance(d, audio.InputDevice) for d in devices)
    if any(d.usable for d in devices):
        pytest.skip("this machine has a microphone; the no-microphone message cannot be checked")
    with pytest.raises(AudioUnavailable, match="no microphone found"):
        audio.default_input_device()


def test_endpointer_finds_one_utterance_with_hangover():
    signal = np.concatenate([_silence(1.0), _tone(0.6, -20), _silence(1.0)])
    ep = Endpointer()
    events = []
    for i in range(0, len(signal) - FRAME_SAMPLES + 1, FRAME_SAMPLES):
        if (event := ep.push(signal[i : i + FRAME_SAMPLES])) is not None:
            events.append((event, (i + FRAME_SAMPLES) / SAMPLE_RATE))
    assert [e for e, _ in events] == ["start", "end"]
    start, end = events[0][1], events[1][1]
    assert 1.0 < start < 1.15  # 90 ms of speech needed to start
    assert end == pytest.approx(1.6 + 0.5, abs=0.04)  # speech end + 500 ms hangover


def test_endpointer_ends_early_only_after_a_whole_answer():
    """After a whole answer 240 ms of quiet end the utterance; mid-answer it waits 500 ms."""
    signal = np.concatenate([_silence(1.0), _tone(0.6, -20), _silence(1.0)])
    for complete, hangover in ((True, 0.24), (False, 0.5)):
        ep = Endpointer()
        ends = [
            (i + FRAME_SAMPLES) / SAMPLE_RATE
            for i in range(0, len(signal) - FRAME_SAMPLES + 1, FRAME_SAMPLES)
            if ep.push(signal[i : i + FRAME_SAMPLES], complete) == "end"
        ]
        assert ends == [pytest.approx(1.6 + hangover, abs=0.04)], complete


def test_pipeline_ends_early_when_the_recogniser_has_a_whole_answer():
    class WholeAnswer(_Recorder):
        """Says its partial result is a whole answer once it has heard 0.4 s."""

        def accept(self, pcm: bytes):
            super().accept(pcm)
            return Recognition("independent", 0.0, final=False, complete=len(self.heard) > 0.4 * 2 * SAMPLE_RATE)

    got = []
    pipe = UtterancePipeline(WholeAnswer(), got.append)
    pipe.feed(np.concatenate([_silence(1.0), _tone(0.5, -20), _silence(1.0)]).tobytes())
    (utt,) = got
    assert utt.complete
    assert utt.endpoint - utt.speech_end == pytest.approx(0.24, abs=0.04)


def test_endpointer_ignores_a_click_and_quiet_hum():
    signal = np.concatenate([_silence(0.5), _tone(0.03, -10), _tone(2.0, -60), _silence(0.5)])
    ep = Endpointer()
    events = [
        ep.push(signal[i : i + FRAME_SAMPLES])
        for i in range(0, len(signal), FRAME_SAMPLES)
        if len(signal[i : i + FRAME_SAMPLES]) == FRAME_SAMPLES
    ]
    assert [e for e in events if e] == []


def test_pipeline_passes_preroll_speech_and_hangover_and_mutes():
    got = []
    rec = _Recorder()
    pipe = UtterancePipeline(rec, got.append)
    speech = np.concatenate([_silence(1.0), _tone(0.5, -20), _silence(1.0)]).tobytes()
    pipe.feed(speech[:12345])  # arbitrary chunk sizes, not frame-aligned
    pipe.feed(speech[12345:])
    assert len(got) == 1
    utt = got[0]
    assert utt.speech_start == pytest.approx(1.0, abs=0.04)
    assert utt.speech_end == pytest.approx(1.5, abs=0.04)
    assert utt.endpoint == pytest.approx(2.0, abs=0.04)
    # the recogniser heard 300 ms of pre-roll, the speech and the hangover
    assert utt.result / SAMPLE_RATE == pytest.approx(0.3 + 0.5 + 0.5, abs=0.06)

    pipe.muted = True
    pipe.feed(speech)
    assert len(got) == 1, "the kiosk's own voice must not become an utterance"
    pipe.muted = False
    pipe.feed(speech)
    assert len(got) == 2


def test_each_utterance_says_how_far_the_voice_stood_above_the_room():
    """The speech's own power (its loud frames' less the room's) over the room's, the room being
    what was heard outside utterances just before: about 20 dB for a tone 20 dB above a steady
    hiss, and not known when the microphone had only just opened."""
    rng = np.random.default_rng(4)

    def hiss(seconds: float) -> np.ndarray:
        return rng.normal(0, 32768 * 10 ** (-60 / 20), int(seconds * SAMPLE_RATE))

    got = []
    pipe = UtterancePipeline(_Recorder(), got.append)
    signal = np.concatenate([hiss(2.0), hiss(0.5) + _tone(0.5, -40), hiss(1.5)])
    pipe.feed(np.round(signal).astype(np.int16).tobytes())
    (utt,) = got
    assert utt.room_db == pytest.approx(-60, abs=0.5)
    # the tone and the hiss under it; the hangover's few hiss frames above the room's ceiling
    # (its 90th percentile) count too, and take a little off
    assert utt.speech_db == pytest.approx(10 * np.log10(10**-4 + 10**-6), abs=1.0)
    assert utt.above_room_db == pytest.approx(20, abs=1.0)
    # as loud as the room, and a room not yet heard
    assert audio.Utterance(0, 0, 0, 0, 0, speech_db=-50.0, room_db=-50.0).above_room_db == -30
    got.clear()
    pipe = UtterancePipeline(_Recorder(), got.append)
    pipe.feed(np.concatenate([_tone(0.5, -40), _silence(1.0)]).tobytes())
    (utt,) = got
    assert utt.room_db is None and utt.above_room_db is None


@pytest.mark.slow  # real audio (espeak-ng)
def test_read_wav_resamples_espeak_output(spoken):
    path = spoken("two")
    with wave.open(str(path)) as w:
        native = w.getnframes() / w.getframerate()
        assert w.getframerate() != SAMPLE_RATE  # the resampler is really exercised
    samples = read_wav(path)
    assert len(samples) / SAMPLE_RATE == pytest.approx(native, abs=0.01)
    got = []
    feed_wav(path, UtterancePipeline(_Recorder(), got.append))
    assert len(got) == 1


def test_read_wav_rejects_non_wav_with_the_file_name(tmp_path):
    path = tmp_path / "answer.wav"
    path.write_bytes(b"not a wav at all")
    with pytest.raises(ValueError, match="answer.wav: not a PCM WAV file"):
        read_wav(path)
