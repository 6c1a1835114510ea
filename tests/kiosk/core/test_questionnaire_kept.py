"""A questionnaire that loaded is kept in a private cache directory and read back on the next
start without composing its YAML; an edit to the file, a problem, or a damaged kept file means
loading it again, so what the kiosk gets or is told is what loading gives."""

from __future__ import annotations

import stat

import pytest

from fileio import positions
from kiosk.core.questionnaire import QuestionnaireError, bundled_path, load_questionnaire
from kiosk.core.questionnaire import loading as questionnaire_loading
from kiosk.core.questionnaire.kept import load_questionnaire_kept


@pytest.fixture
def kept_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    return tmp_path / "cache" / "kiosk" / "questionnaires"


@pytest.fixture
def barthel(tmp_path):
    path = tmp_path / "barthel.yaml"
    path.write_text(bundled_path().read_text(encoding="utf-8"), encoding="utf-8")
    return path


def _no_parsing(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the questionnaire was parsed again")

    monkeypatch.setattr(questionnaire_loading, "parse_file", refuse)
    monkeypatch.setattr(positions, "parse_file", refuse)


def test_a_loaded_questionnaire_is_kept_private_and_read_back_without_parsing(kept_dir, barthel, monkeypatch):
    first = load_questionnaire_kept(barthel)
    (kept,) = kept_dir.glob("*.pickle")
    assert stat.S_IMODE(kept_dir.stat().st_mode) == 0o700 and stat.S_IMODE(kept.stat().st_mode) == 0o600
    _no_parsing(monkeypatch)
    again = load_questionnaire_kept(barthel)
    assert again is not first and again == first
    monkeypatch.undo()
    assert again == load_questionnaire(barthel)  # what loading gives


def test_an_edited_file_is_loaded_again_and_its_problems_reported_every_time(kept_dir, barthel):
    before = load_questionnaire_kept(barthel)
    text = barthel.read_text(encoding="utf-8")
    barthel.write_text(text.replace(before.items[0].id, "renamed_item", 1), encoding="utf-8")
    assert load_questionnaire_kept(barthel).items[0].id == "renamed_item"
    barthel.write_text(text.replace("items:", "itemz:", 1), encoding="utf-8")
    for _ in range(2):  # a problem is never kept
        with pytest.raises(QuestionnaireError):
            load_questionnaire_kept(barthel)


def test_a_damaged_kept_questionnaire_is_loaded_again(kept_dir, barthel):
    first = load_questionnaire_kept(barthel)
    (kept,) = kept_dir.glob("*.pickle")
    kept.write_bytes(b"not a questionnaire\n")
    assert load_questionnaire_kept(barthel) == first
    assert kept.read_bytes() != b"not a questionnaire\n"
