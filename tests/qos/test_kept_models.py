"""A model that parsed is kept in a private cache directory and read back on the next load, with
neither lark nor a parse; a change to the model or to a model it imports, an error, or a damaged
kept file means parsing again, so what a load returns or raises is what parsing gives."""

from __future__ import annotations

import os
import stat
import subprocess
import sys

import pytest

from qos import ModelError, load_model


@pytest.fixture
def kept_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    return tmp_path / "cache" / "kiosk" / "qos-models"


@pytest.fixture
def models(tmp_path):
    folder = tmp_path / "models"
    folder.mkdir()
    (folder / "base.roqme").write_text("roqme Base\nproperty P\ncontext B : boolean\n", encoding="utf-8")
    (folder / "top.roqme").write_text('roqme Top\nimport "base.roqme"\nobservation O : B reinforces P\n')
    return folder


def _shape(model):
    return model.name, list(model.properties), list(model.contexts), list(model.observations)


def test_a_parsed_model_is_kept_private_and_read_back_unchanged(kept_dir, models):
    first = load_model(models / "top.roqme")
    (kept,) = kept_dir.glob("*.pickle")
    assert stat.S_IMODE(kept_dir.stat().st_mode) == 0o700 and stat.S_IMODE(kept.stat().st_mode) == 0o600
    written = kept.stat().st_mtime_ns
    again = load_model(models / "top.roqme")
    assert again is not first and _shape(again) == _shape(first) == ("Top", ["P"], ["B"], ["O"])
    assert kept.stat().st_mtime_ns == written  # read back, not parsed and written again
    assert os.listdir(kept_dir) == [kept.name]


def test_a_changed_import_is_parsed_again_and_its_error_reported(kept_dir, models):
    load_model(models / "top.roqme")
    (models / "base.roqme").write_text("roqme Base\nproperty P\nproperty Q\ncontext B : boolean\n")
    assert list(load_model(models / "top.roqme").properties) == ["P", "Q"]
    (models / "base.roqme").write_text("roqme Base\nproperty P\ncontext B : bool\n")
    with pytest.raises(ModelError, match=r"^base\.roqme:3:13: unknown type bool"):
        load_model(models / "top.roqme")
    with pytest.raises(ModelError, match=r"^base\.roqme:3:13: unknown type bool"):
        load_model(models / "top.roqme")  # an error is never kept


def test_a_damaged_kept_model_is_parsed_again(kept_dir, models):
    load_model(models / "top.roqme")
    (kept,) = kept_dir.glob("*.pickle")
    kept.write_bytes(b"not a model\n")
    assert _shape(load_model(models / "top.roqme")) == ("Top", ["P"], ["B"], ["O"])
    assert kept.read_bytes() != b"not a model\n"


def test_a_cache_directory_others_may_write_is_not_used(kept_dir, models):
    kept_dir.mkdir(parents=True)
    kept_dir.chmod(0o777)
    assert _shape(load_model(models / "top.roqme"))[0] == "Top"
    assert list(kept_dir.iterdir()) == []


@pytest.mark.slow  # fresh interpreters, as two starts of the kiosk
def test_the_second_load_needs_no_lark(tmp_path):
    code = "import sys\nfrom qos import load_model\nload_model('kiosk_pace')\nprint('lark' in sys.modules)\n"
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path))
    runs = [subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True) for _ in range(2)]
    assert [run.stdout.strip() for run in runs] == ["True", "False"], [run.stderr for run in runs]
