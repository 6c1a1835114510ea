"""The kiosk's words, one file per language: adding a language is adding a file, and a file that
differs from en.yaml is refused with each difference as one ``file:line:col`` problem."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from kiosk.commands.validate import main as validate_main
from kiosk.config import ConfigError, load_config
from kiosk.core import words as words_module
from kiosk.core.channels import Command
from kiosk.core.words import WORDS_DIR, WordsError, check_words, languages, load_words

ROOT = Path(__file__).resolve().parents[3]


def words_dir(tmp_path: Path) -> Path:
    """A copy of the kiosk's words files, to add to and break."""
    directory = tmp_path / "words"
    directory.mkdir()
    for path in WORDS_DIR.glob("*.yaml"):
        shutil.copy(path, directory)
    return directory


def add_language(directory: Path, code: str = "xx") -> Path:
    """A new language: en.yaml copied under the new code, with its own name, voice and a word changed."""
    text = (WORDS_DIR / "en.yaml").read_text(encoding="utf-8")
    text = text.replace("  code: en\n", f"  code: {code}\n").replace("  name: English\n", "  name: Xish\n")
    text = text.replace("  voice: gmw/en-us\n", "  voice: gmw/en-gb\n").replace("  start: Start\n", "  start: Go\n")
    path = directory / f"{code}.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def position(path: Path, line_text: str) -> str:
    """``file:line:col`` of the first line holding ``line_text``, at its first non-blank column."""
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        if line_text in line:
            return f"{path}:{number}:{len(line) - len(line.lstrip()) + 1}"
    raise AssertionError(f"{line_text!r} not in {path}")


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert old in text, old
    path.write_text(text.replace(old, new, 1), encoding="utf-8")


def test_the_kiosk_speaks_the_languages_whose_files_are_present():
    assert languages() == ("de", "en", "es", "fr")
    words = load_words()
    assert [(w.code, w.name, w.voice) for w in words.values()] == [
        ("de", "Deutsch", "gmw/de"),
        ("en", "English", "gmw/en-us"),
        ("es", "Español", "roa/es"),
        ("fr", "Français", "roa/fr"),
    ]
    assert words["fr"].screen["start"] == "Commencer" and words["es"].export["total_score"] == "Puntuación total"
    # every file has exactly en.yaml's screen keys (the check refuses any other), and the commands are the kiosk's
    assert {frozenset(w.screen) for w in words.values()} == {frozenset(words["en"].screen)}
    assert set(words_module.COMMANDS) == {command.value for command in Command}


def test_adding_a_language_is_adding_a_file(tmp_path, capsys):
    directory = words_dir(tmp_path)
    add_language(directory)
    words, problems, readable = check_words(directory)
    assert problems == [] and readable
    assert list(words) == ["de", "en", "es", "fr", "xx"]
    assert (words["xx"].name, words["xx"].voice, words["xx"].screen["start"]) == ("Xish", "gmw/en-gb", "Go")
    assert validate_main(["--words", str(directory)]) == 0
    assert f"{directory}: ok, languages de, en, es, fr, xx" in capsys.readouterr().err


def test_a_file_missing_a_key_is_refused_naming_where_and_the_key(tmp_path, capsys):
    directory = words_dir(tmp_path)
    new = add_language(directory)
    edit(new, "  paused_title: Paused\n", "")
    where = position(new, "screen:")
    _, problems, readable = check_words(directory)
    assert readable and [str(p) for p in problems] == [f"{where}: missing 'screen.paused_title' (en.yaml has it)"]
    with pytest.raises(WordsError) as refused:  # nothing half-loaded: no language at all
        load_words(directory)
    assert str(refused.value) == str(problems[0])
    assert validate_main(["--words", str(directory)]) == 1
    out, err = capsys.readouterr()
    assert out.splitlines() == [str(problems[0])] and "ok" not in err


@pytest.mark.parametrize(
    ("old", "new", "at", "message"),
    [
        ("  paused_text:", "  paused_txt: x\n  paused_text:", "paused_txt", "unknown key 'screen.paused_txt'"),
        ("{total} of {maximum}", "{total} of {max}", "summary_total", "must have the placeholders of en.yaml"),
        ("Question {number} of", "Question {number of", "question_of", "a brace without its pair"),
        ("Answer by {ways}.", "Answer by {ways:>999999999}.", "answer_by", "{ways:>999999999} is not a placeholder"),
        ("Answer by {ways}.", "Answer by {0.__class__}.", "answer_by", "{0.__class__} is not a placeholder"),
        ("Answer by {ways}.", "Answer by {ways!r}.", "answer_by", "{ways!r} is not a placeholder"),
        ("  title: Barthel questionnaire", "  title: [Barthel]", "title:", "screen.title must be text"),
        ('  yes_label: "Yes"', "  yes_label: yes", "yes_label", "prompts.yes_label must be text"),
        ("[[one], [two],", "[[one],", "cardinals", "speech.cardinals must have the words for 10 numbers"),
        ('"number {n}"', '"number"', '"number"', "speech.number_forms[1] must hold {n} or {o}"),
        ("  lead_ins: [", "  lead_ins: [3, ", "lead_ins", "speech.lead_ins must be a list of words (or [])"),
        (
            "    fr: [French]\n",
            "    fr: [French]\n    pt: [Portuguese]\n",
            "pt: [Portuguese]",
            "no words file for 'pt'",
        ),
        ("  code: xx", "  code: en", "code:", "language.code is 'en' but the file is xx.yaml"),
        (
            'no_words: ["no", nope, no that\'s wrong',
            'no_words: ["no", yeah, no that\'s wrong',
            'no_words: ["no", yeah',
            "prompts.no_words: 'yeah' is also one of the yes_words",
        ),
        ("pause: [pause, wait, stop]", "pause: [pause, wait, nope]", "pause: [pause", "'nope' is also one of"),
        ("  start: Go\n", "  start: Go\n  start: Went\n", "start: Went", "duplicate key 'start'"),
    ],
)
def test_each_difference_from_en_yaml_is_one_positioned_problem(tmp_path, old, new, at, message):
    directory = words_dir(tmp_path)
    path = add_language(directory)
    edit(path, old, new)
    _, problems, _ = check_words(directory)
    assert len(problems) == 1, problems
    assert str(problems[0]).startswith(position(path, at).rsplit(":", 1)[0] + ":") and message in problems[0].message


def test_a_format_spec_in_the_template_is_refused_by_validate_and_never_formatted(tmp_path, capsys):
    directory = words_dir(tmp_path)
    template = directory / "en.yaml"
    edit(template, "Answer by {ways}.", "Answer by {ways:>999999999}.")
    assert validate_main(["--words", str(directory)]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == (
        f"{position(template, 'answer_by').rsplit(':', 1)[0]}:14: screen.answer_by: {{ways:>999999999}} is not a "
        "placeholder: a placeholder is a name in braces, like {ways}, with no format, index or attribute "
        "(write {{ or }} for a brace)"
    )
    # and were such a text ever filled, only {name} marks are: the spec stays as written
    from kiosk.core.words import fill

    assert fill("Answer by {ways:>999999999}, {ways} {{x}} {0.__class__}", ways="touch") == (
        "Answer by {ways:>999999999}, touch {x} {0.__class__}"
    )


def test_a_key_deleted_from_the_template_is_reported_there_not_in_every_other_file(tmp_path):
    directory = words_dir(tmp_path)
    template = directory / "en.yaml"
    edit(template, "  paused_title: Paused\n", "")
    _, problems, readable = check_words(directory)
    assert readable and [str(p) for p in problems] == [
        f"{position(template, 'screen:')}: missing 'screen.paused_title' (every other language has it, "
        "and the screens need it)"
    ]


def test_a_broken_template_is_reported_in_the_template_only(tmp_path):
    directory = words_dir(tmp_path)
    template = directory / "en.yaml"
    text = template.read_text(encoding="utf-8")
    template.write_text(text[: text.index("\nscreen:\n")] + "\nscreen: none\n" + text[text.index("\nprompts:") :])
    _, problems, _ = check_words(directory)
    assert [str(p) for p in problems] == [
        f"{position(template, 'screen: none').rsplit(':', 1)[0]}:9: screen must be a mapping"
    ]


def test_unreadable_or_misnamed_files_and_a_missing_template_are_refused(tmp_path, capsys):
    directory = words_dir(tmp_path)
    (directory / "xx.yaml").write_bytes(b"language: {code: xx\x00}\n")
    (directory / "english.yaml").write_text("language: {}\n")
    _, problems, readable = check_words(directory)
    assert not readable
    assert [(Path(p.file).name, p.line) for p in problems] == [("english.yaml", 1), ("xx.yaml", 1)]
    assert "not named by a language code" in problems[0].message and "NUL" in problems[1].message
    assert validate_main(["--words", str(directory)]) == 2
    (directory / "en.yaml").unlink()
    _, problems, _ = check_words(directory)
    assert (
        str(problems[-1]) == f"{directory / 'en.yaml'}:1:1: missing: every language's words file is checked against it"
    )


def test_a_bad_words_file_stops_the_configuration_with_its_position(tmp_path, monkeypatch):
    directory = words_dir(tmp_path)
    edit(directory / "es.yaml", "  paused_title: En pausa\n", "")
    monkeypatch.setattr(words_module, "WORDS_DIR", directory)
    words_module._kiosk_words.cache_clear()  # read the kiosk's words again, from the copy
    try:
        with pytest.raises(ConfigError, match=re.escape(position(directory / "es.yaml", "screen:"))):
            load_config(environ={})
    finally:
        monkeypatch.undo()
        words_module._kiosk_words.cache_clear()
    assert list(load_words()) == ["de", "en", "es", "fr"]


def test_every_screen_text_the_screens_name_is_in_en_yaml():
    """en.yaml is what every other file is checked against, so it must hold every key a screen asks for."""
    named = set()
    for path in (ROOT / "kiosk" / "ui").rglob("*.py"):
        named |= set(re.findall(r"ui_text\(\s*[\w.]+,\s*[\"'](\w+)[\"']", path.read_text(encoding="utf-8")))
    assert len(named) >= 20  # the pattern still finds the screens' texts
    assert named - set(load_words()["en"].screen) == set()


#: run in a fresh interpreter whose kiosk reads its words from argv[1]: everything a patient meets
#: in a language (prompts, voice, screens, configuration, instrument checks) comes from the files
PROBE = r"""
import json, sys
from pathlib import Path
import kiosk.core.words
kiosk.core.words.WORDS_DIR = Path(sys.argv[1])
from kiosk.config import ConfigError, load_config
from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.clock import SimClock
from kiosk.core.questionnaire import check_questionnaire, load_questionnaire
from kiosk.core.session import Prompt, Session
from kiosk.speech.matching import Matcher, OptionWords
from kiosk.speech.tts import VOICES
from kiosk.ui.widgets.text import language_name, ui_text

prompts = []
clock = SimClock(1.0)
session = Session(load_questionnaire(sys.argv[2]), clock=clock, engine=None, patient_id="T-0001", familiarisation=False)
session.subscribe(lambda event: prompts.append(event) if isinstance(event, Prompt) else None)
session.welcome()
welcome = prompts[-1]
heard = Matcher([OptionWords(o.label, o.synonyms) for o in welcome.options], "en").match("Xish")
session.handle(ChannelInput(Channel.VOICE, option=heard.option, detail="Xish"))
explanation = prompts[-1]
try:
    load_config(environ={"KIOSK_LANGUAGE": "zz"})
    refused = ""
except ConfigError as exc:
    refused = str(exc)
print(json.dumps({
    "welcome": [o.label for o in welcome.options],
    "language": session.language,
    "explanation": [explanation.language, [o.label for o in explanation.options]],
    "ready": Matcher([OptionWords(o.label, o.synonyms) for o in explanation.options], "xx").match("I'm ready").option,
    "config": load_config(environ={"KIOSK_LANGUAGE": "xx"}).language,
    "refused": refused,
    "screen": [ui_text("xx", "start"), language_name("xx"), ui_text("xx", "question_of", number=1, total=10)],
    "voice": VOICES["xx"],
    "instrument": [str(p) for p in check_questionnaire(sys.argv[2])[1]],
}))
"""


def test_a_new_words_file_is_all_a_new_language_needs(tmp_path):
    import json
    import subprocess
    import sys

    import yaml

    from kiosk.core.questionnaire import bundled_path

    directory = words_dir(tmp_path)
    add_language(directory)
    data = yaml.safe_load(bundled_path().read_text(encoding="utf-8"))

    def with_xx(value):  # the instrument's translation: here its English texts under the new code
        if isinstance(value, dict):
            inner = {key: with_xx(v) for key, v in value.items()}
            return {**inner, "xx": inner["en"]} if "en" in value and set(value) <= {"en", "es", "fr", "de"} else inner
        return [with_xx(v) for v in value] if isinstance(value, list) else value

    data = with_xx(data)
    data["languages"] = [*data["languages"], "xx"]
    instrument = tmp_path / "barthel-xx.yaml"
    instrument.write_text(yaml.safe_dump(data, allow_unicode=True, sort_keys=False), encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-c", PROBE, str(directory), str(instrument)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)},
        timeout=120,  # a guard against a hang, not a timing assertion
    )
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout)
    assert seen["welcome"] == ["English", "Español", "Français", "Deutsch", "Xish"]
    assert seen["language"] == "xx" and seen["explanation"] == ["xx", ["Go"]] and seen["ready"] == 1
    assert seen["config"] == "xx" and "language 'zz' is not one of de, en, es, fr, xx" in seen["refused"]
    assert seen["screen"] == ["Go", "Xish", "Question 1 of 10"] and seen["voice"] == "gmw/en-gb"
    assert seen["instrument"] == []
    # the kiosk's own words have no such file, so the same instrument is refused there
    assert validate_main([str(instrument)]) == 1


def test_checked_words_are_kept_and_read_back_without_parsing_a_problem_never(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    directory = words_dir(tmp_path)
    first = words_module.kept_data(directory)
    assert first == words_module._check_files(directory)[0]
    (kept,) = (tmp_path / "cache" / "kiosk" / words_module.KEPT).glob("*.pickle")
    parsed = []
    monkeypatch.setattr(words_module, "parse_file", lambda *a: parsed.append(a))
    assert words_module.kept_data(directory) == first and not parsed
    monkeypatch.undo()
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    en = directory / "en.yaml"
    en.write_text(en.read_text(encoding="utf-8").replace("language:", "langauge:", 1), encoding="utf-8")
    expected = str(WordsError(check_words(directory)[1]))
    for _ in range(2):  # the same message every time: a file with a problem is never kept
        with pytest.raises(WordsError) as raised:
            words_module.kept_data(directory)
        assert str(raised.value) == expected
    assert list(kept.parent.glob("*.pickle")) == [kept]
