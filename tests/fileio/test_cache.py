"""What a start need not do twice: a document that passed its JSON Schema is remembered (in a
private cache directory) and not checked again; one with a problem is checked every time, and
changing a single value means checking again."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from fileio import cache
from fileio.positions import parse, schema_problems
from tests.prerequisites import DEVELOPER_HOME

SCHEMA = {
    "type": "object",
    "properties": {"points": {"type": "integer", "multipleOf": 5}},
    "required": ["points"],
    "additionalProperties": False,
}


@pytest.fixture
def cache_home(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    return tmp_path / "kiosk" / "checked"


def _problems(text: str) -> list[str]:
    data, positions, problems = parse(text, "doc.yaml")
    assert positions is not None and problems == []
    found: list[str] = []
    schema_problems(data, SCHEMA, positions, lambda path, message, key=False: found.append(message))
    return found


def test_a_document_with_a_problem_is_checked_every_time(cache_home):
    assert _problems("points: 7\n") == ["points: must be a multiple of 5, got 7"]
    assert _problems("points: 7\n") == ["points: must be a multiple of 5, got 7"]
    assert not (cache_home / "json-schema").exists()  # nothing remembered for a failing document


def test_a_remembered_document_changed_by_one_value_is_checked_again(cache_home):
    assert _problems("points: 10\n") == []
    assert len((cache_home / "json-schema").read_text().split()) == 1
    assert stat.S_IMODE(cache_home.stat().st_mode) == 0o700
    assert _problems("points: 10\n") == []  # remembered
    assert _problems("points: 11\n") == ["points: must be a multiple of 5, got 11"]
    assert _problems("points: 10\nextra: 1\n") == ["unknown key 'extra'"]


def test_only_the_latest_are_remembered(cache_home):
    keys = [cache.digest(str(n)) for n in range(cache.REMEMBERED + 5)]
    for key in keys:
        cache.remember("json-schema", key)
    assert not cache.passed("json-schema", keys[0])
    assert all(cache.passed("json-schema", key) for key in keys[5:])
    assert os.listdir(cache_home) == ["json-schema"]  # no half-written file left beside it


def test_a_cache_directory_others_may_write_is_not_used(cache_home):
    cache_home.mkdir(parents=True)
    cache_home.chmod(0o777)
    assert _problems("points: 10\n") == []
    assert list(cache_home.iterdir()) == []
    cache.remember("json-schema", "x")
    assert not cache.passed("json-schema", "x")


@pytest.mark.slow  # fresh interpreters, as two starts of the kiosk
def test_the_second_start_loads_the_questionnaire_without_jsonschema(tmp_path):
    code = (
        "import sys\nfrom kiosk.core.questionnaire import load_questionnaire\n"
        "load_questionnaire()\nprint('jsonschema' in sys.modules)\n"
    )
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path))
    runs = [subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True) for _ in range(2)]
    assert [run.stdout.strip() for run in runs] == ["True", "False"], [run.stderr for run in runs]


def test_the_test_run_keeps_its_caches_out_of_the_users_home():
    import platformdirs

    folder = Path(platformdirs.user_cache_dir("kiosk")).resolve()
    assert not folder.is_relative_to(Path(os.environ[DEVELOPER_HOME]).resolve()), folder
    assert folder.is_relative_to(Path(tempfile.gettempdir()).resolve()), folder


def test_a_parsed_document_asked_to_be_kept_is_read_back_without_yaml_one_with_a_problem_never(cache_home, monkeypatch):
    from fileio import yamlfile

    text = "points: 5\nwords: [a, b]\nwhen: 2026-11-26\n"
    parse(text, "doc.yaml")  # kept only when asked
    parse(text, "doc.yaml", keep=lambda data: "points" not in data)  # or when the data may be kept
    assert not (cache_home.parent / "parsed-yaml").exists() or not list((cache_home.parent / "parsed-yaml").iterdir())
    data, positions, problems = parse(text, "doc.yaml", keep=True)
    assert problems == [] and positions is not None
    (kept,) = (cache_home.parent / "parsed-yaml").glob("*.pickle")
    assert stat.S_IMODE(kept.stat().st_mode) == 0o600

    def refuse(*args, **kwargs):
        raise AssertionError("parsed again")

    monkeypatch.setattr(yamlfile, "compose_yaml", refuse)
    again, again_positions, again_problems = parse(text, "other.yaml", keep=True)
    assert (again, again_problems) == (data, []) and again is not data
    assert again_positions is not None and again_positions.of(("words", 1)) == positions.of(("words", 1)) == (2, 12)
    monkeypatch.undo()
    monkeypatch.setenv("XDG_CACHE_HOME", str(cache_home.parent.parent))
    bad = "points: 5\npoints: 6\n"
    for _ in range(2):  # the same problem every time: it is never kept
        assert parse(bad, "doc.yaml", keep=True)[2][0].message == "duplicate key 'points'"
    assert list(kept.parent.glob("*.pickle")) == [kept]


def test_the_cache_folder_and_the_kiosks_folder_above_it_are_owner_only(tmp_path, monkeypatch):
    """Issue 32: ``<cache>/kiosk`` was made 0755 (only the folder below it was 0700)."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "fresh"))
    folder = cache.private_dir("checked")
    assert folder is not None
    assert [oct(stat.S_IMODE(p.stat().st_mode)) for p in (folder.parent, folder)] == ["0o700", "0o700"]
