"""Voice out with the real engine (espeak-ng): every Barthel question in en/es/fr, to WAV."""

from __future__ import annotations

import html
import subprocess
import threading
import wave

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from kiosk.core.channels import Channel, ChannelState, ChannelStatus
from kiosk.core.questionnaire import load_questionnaire
from kiosk.speech.audio import frame_level_db
from kiosk.speech.tts import DEFAULT_RATE, MIN_RATE, Delivery, Speaker, Synthesiser, TtsUnavailable, delivery

QUESTIONNAIRE = load_questionnaire()


def _wav(path) -> tuple[np.ndarray, int]:
    with wave.open(str(path)) as w:
        return np.frombuffer(w.readframes(w.getnframes()), dtype="<i2"), w.getframerate()


class _RecordingPlayer:
    """Stands in for the sound card (none here): keeps what would have been played."""

    def __init__(self) -> None:
        self.played: list[tuple[np.ndarray, int]] = []
        self.stopped = threading.Event()

    def play(self, samples, rate) -> None:
        self.played.append((samples, rate))

    def stop(self) -> None:
        self.stopped.set()


@pytest.fixture(scope="module")
def tts_speaker(espeak_ng):
    speaker = Speaker()
    speaker.start()
    speaker.wait_ready()
    yield speaker
    speaker.close()


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("language", ["en", "es", "fr", "de"])
def test_every_question_is_real_speech_of_plausible_length(tts_speaker, tmp_path, language):
    total_seconds = total_expected = 0.0
    for item in QUESTIONNAIRE.items:
        text = item.spoken[language]
        path = tts_speaker.save_to_file(text, language, tmp_path / f"{item.id}.wav")
        samples, rate = _wav(path)
        seconds = len(samples) / rate
        words = len(text.split())
        expected = words * 60 / DEFAULT_RATE
        # espeak-ng's words-per-minute assume words of average length: a question of short
        # words ("How do you get from your bed to a chair and back?") runs faster, commas add
        # pauses; per question only a gross error is caught, the rate is checked over all ten
        assert 0.5 * expected <= seconds <= 1.5 * expected + 0.6, (item.id, words, seconds)
        total_seconds, total_expected = total_seconds + seconds, total_expected + expected
        frame = rate // 50  # 20 ms
        levels = [frame_level_db(samples[i : i + frame]) for i in range(0, len(samples) - frame, frame)]
        voiced = sum(level > -40 for level in levels) / len(levels)
        assert frame_level_db(samples) > -30, item.id  # loud enough to be speech, not hiss
        assert voiced > 0.5, (item.id, voiced)  # mostly speech, with pauses between words
    # all ten questions together: about 160 words per minute
    assert 0.75 <= total_seconds / total_expected <= 1.25, total_seconds / total_expected


@pytest.mark.slow  # real audio (espeak-ng)
def test_languages_sound_different(tts_speaker, tmp_path):
    """Each language gets its own voice: the same text is not read the same way."""
    lengths = {
        lang: len(_wav(tts_speaker.save_to_file("Independiente", lang, tmp_path / f"{lang}.wav"))[0])
        for lang in ("en", "es", "fr")
    }
    assert len(set(lengths.values())) == 3


@pytest.mark.slow  # real audio (espeak-ng)
def test_rate_and_volume_change_the_speech(tmp_path, espeak_ng):
    speaker = Speaker(rate=DEFAULT_RATE)
    speaker.start()
    text = QUESTIONNAIRE.items[0].spoken["en"]
    normal = _wav(speaker.save_to_file(text, "en", tmp_path / "normal.wav"))[0]
    speaker.volume_down()
    speaker.volume_down()
    quiet = _wav(speaker.save_to_file(text, "en", tmp_path / "quiet.wav"))[0]
    speaker.rate = 250
    fast = _wav(speaker.save_to_file(text, "en", tmp_path / "fast.wav"))[0]
    speaker.close()
    assert frame_level_db(quiet) < frame_level_db(normal) - 3
    assert len(fast) < 0.8 * len(normal)


def _voiced_words_per_minute(samples: np.ndarray, rate: int, words: int) -> float:
    """Words per minute of voiced audio (20 ms frames above -40 dBFS): the words' own pace."""
    frame = rate // 50
    voiced = sum(frame_level_db(samples[i : i + frame]) > -40 for i in range(0, len(samples) - frame, frame))
    return words * 60 / (voiced * 0.02)


@pytest.mark.slow  # real audio (espeak-ng)
def test_slower_speech_is_pauses_not_slower_words(tmp_path, espeak_ng):
    """slow_speech asks for 0.85 x 160 = 136 wpm: the prompt takes longer, its words do not."""
    text = f"{QUESTIONNAIRE.message('repeat', 'en')} {QUESTIONNAIRE.items[0].spoken['en']}"
    words = len(text.split())
    speaker = Speaker()
    speaker.start()
    normal = _wav(speaker.save_to_file(text, "en", tmp_path / "normal.wav"))
    speaker.rate = round(DEFAULT_RATE * 0.85)
    slow = _wav(speaker.save_to_file(text, "en", tmp_path / "slow.wav"))
    speaker.close()
    # espeak-ng asked for 136 wpm outright: what the kiosk no longer does
    plain = _wav(_espeak(text, 136, tmp_path / "136.wav"))
    assert len(slow[0]) / slow[1] > len(normal[0]) / normal[1] + 0.4  # longer, by pauses
    slow_pace = _voiced_words_per_minute(*slow, words)
    assert slow_pace >= MIN_RATE
    assert slow_pace > _voiced_words_per_minute(*plain, words) + 10  # words kept at their pace


def _espeak(text: str, rate: int, path):
    """espeak-ng's own slowing: the words themselves at ``rate``."""
    subprocess.run(["espeak-ng", "-v", "gmw/en-us", "-s", str(rate), "-w", str(path), "--", text], check=True)
    return path


def test_delivery_maps_slow_rates_to_pauses():
    assert delivery(DEFAULT_RATE, "Hello. How are you?") == Delivery(DEFAULT_RATE)
    assert delivery(MIN_RATE, "Hello. How are you?") == Delivery(MIN_RATE)
    # no sentence end or comma inside: only the words' pace can slow, and not below 150 wpm
    assert delivery(100, "How do you manage eating your meals?") == Delivery(MIN_RATE)
    # 7 words at 136 instead of 150 wpm: 288 ms more, 2 shares after "again." and 1 after ","
    slow = delivery(136, "Let me ask again. Eating, with help?")
    assert slow.words_per_minute == MIN_RATE
    assert slow.sentence_break_ms - 400 == pytest.approx(2 * (slow.comma_break_ms - 150), abs=1)
    assert (slow.sentence_break_ms - 400) + (slow.comma_break_ms - 150) == pytest.approx(
        1000 * 7 * (60 / 136 - 60 / 150), abs=2
    )
    assert slow.markup("Fish & chips, <now>. Yes") == (
        f'<speak>Fish &amp; chips,<break time="{slow.comma_break_ms}ms"/> &lt;now&gt;.'
        f'<break time="{slow.sentence_break_ms}ms"/> Yes</speak>'
    )


@given(st.text(alphabet=st.sampled_from("ab &<>\"'\u00e9#x"), max_size=30))
def test_a_slowed_prompt_escapes_its_text_as_html_would(text):
    slow = delivery(100, text)
    assert slow.markup(text) == f"<speak>{html.escape(text, quote=False)}</speak>"


def test_volume_steps_stay_in_range():
    speaker = Speaker()
    volumes = [speaker.volume_up() for _ in range(10)]
    assert volumes[-1] == 2.0 and volumes == sorted(volumes)
    assert [speaker.volume_down() for _ in range(20)][-1] == 0.25


def test_speech_start_and_end_bracket_playback():
    events: list[object] = []
    statuses = []
    player = _RecordingPlayer()
    done = threading.Event()

    def on_speech(speaking: bool) -> None:
        events.append(("speaking", speaking, len(player.played)))
        if not speaking:
            done.set()

    speaker = Speaker(on_status=statuses.append, on_speech=on_speech, player_factory=lambda: player)
    speaker.start()
    speaker.say(QUESTIONNAIRE.items[1].spoken["fr"], "fr")
    assert done.wait(10)
    speaker.close()
    assert [s.state for s in statuses] == [ChannelState.ON]
    # muted before the first sample is played, unmuted only after the last
    assert events == [("speaking", True, 0), ("speaking", False, 1)]
    samples, rate = player.played[0]
    assert rate == 22050 and len(samples) / rate > 2


def test_no_audio_output_turns_voice_out_off_without_crashing(tmp_path):
    statuses = []
    speaker = Speaker(on_status=statuses.append)
    speaker.start()
    if speaker.wait_ready():
        speaker.close()
        pytest.skip("this machine has an audio output; the no-output path cannot be checked")
    speaker.say("Hello", "en")  # ignored, not an error
    # synthesis to a file still works: the tests above rely on it
    assert speaker.save_to_file("Hello", "en", tmp_path / "hello.wav").stat().st_size > 1000
    speaker.close()
    (status,) = statuses
    assert (status.channel, status.state, status.source) == (Channel.VOICE, ChannelState.OFF, "espeak-ng")
    assert status.reason == "voice out off: no audio output found"


@pytest.mark.slow  # real audio (espeak-ng)
def test_unknown_language_is_a_clear_error(tts_speaker, tmp_path):
    with pytest.raises(TtsUnavailable, match="no voice for language 'xx'"):
        tts_speaker.save_to_file("Hallo", "xx", tmp_path / "x.wav")


def test_a_failing_loudspeaker_is_reported_and_the_next_phrase_still_plays():
    class FlakyPlayer(_RecordingPlayer):
        def play(self, samples, rate):
            if not self.played:
                self.played.append(None)
                raise OSError("PortAudio: device unavailable")
            super().play(samples, rate)

    player = FlakyPlayer()
    statuses = []
    ended = threading.Semaphore(0)
    speaker = Speaker(
        on_status=statuses.append, player_factory=lambda: player, on_speech=lambda s: None if s else ended.release()
    )
    speaker.start()
    speaker.say("First", "en")
    speaker.say("Second", "en")
    assert ended.acquire(timeout=10) and ended.acquire(timeout=10)
    speaker.close()
    # the second phrase was heard: voice out is on again, not lost for good
    assert [s.state for s in statuses] == [ChannelState.ON, ChannelState.LOST, ChannelState.ON]
    assert statuses[1].reason == "voice out failed: PortAudio: device unavailable"
    assert len(player.played) == 2 and player.played[1] is not None


def test_stop_speaking_drops_the_phrase_being_synthesised(monkeypatch):
    """The patient answers while a phrase is still being synthesised (already off the queue,
    the player idle): it is never played, and the next phrase is."""
    synthesising, stopped = threading.Event(), threading.Event()
    real = Synthesiser.synthesise

    def held_synthesise(self, *args, **kwargs):
        synthesising.set()
        assert stopped.wait(10)  # hold the first phrase in synthesis until stop_speaking ran
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Synthesiser, "synthesise", held_synthesise)
    player = _RecordingPlayer()
    events: list[bool] = []
    ended = threading.Event()
    speaker = Speaker(player_factory=lambda: player, on_speech=lambda s: (events.append(s), None if s else ended.set()))
    speaker.start()
    speaker.say("How do you manage eating your meals?", "en")
    assert synthesising.wait(10)
    speaker.stop_speaking()
    stopped.set()
    speaker.say("Two", "en")
    assert ended.wait(10)
    speaker.close()
    assert events == [True, False]  # no start/end events for the dropped phrase
    (played,) = player.played
    assert len(played[0]) / played[1] < 1.5  # "Two", not the question


def test_without_espeak_ng_voice_out_is_off_and_says_why(monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))  # a machine where espeak-ng is not installed
    statuses = []
    speaker = Speaker(on_status=statuses.append, player_factory=_RecordingPlayer)
    speaker.start()
    assert not speaker.wait_ready()
    speaker.say("Hello", "en")  # ignored, not an error
    with pytest.raises(TtsUnavailable, match="espeak-ng is not installed"):
        speaker.save_to_file("Hello", "en", tmp_path / "x.wav")
    speaker.close()
    assert statuses == [
        ChannelStatus(
            Channel.VOICE, ChannelState.OFF, source="espeak-ng", reason="voice out off: espeak-ng is not installed"
        )
    ]
