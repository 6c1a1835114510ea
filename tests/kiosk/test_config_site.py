"""A site's own folder (``site_dir:``): its instruments, new languages and QoS models, checked
whole when the configuration is read and by `kiosk validate`, with real files in tmp folders."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from kiosk.config import configured_instruments, load_config
from kiosk.core.qos_model import load_kiosk_model
from kiosk.core.questionnaire.loading import bundled_path
from kiosk.core.session.words import START_LABEL
from kiosk.core.words import WORDS_DIR, languages
from tests.kiosk.battery_instruments import write_mini
from tests.kiosk.command_line import kiosk
from tests.kiosk.configs import refusal

#: a site's QoS model that declares the kiosk's contexts by importing the shipped CLARC model
WARD_MODEL = 'roqme Ward\n\nimport "clarc.roqme"\n\nproperty Calm reference 0.5\n'


def _with_portuguese(value: Any) -> Any:
    """Every per-language mapping of an instrument with an (untranslated) Portuguese entry."""
    if isinstance(value, list):
        return [_with_portuguese(v) for v in value]
    if not isinstance(value, dict):
        return value
    value = {k: _with_portuguese(v) for k, v in value.items()}
    if "en" in value and set(value) <= {"en", "es", "fr", "de"}:
        value["pt"] = value["en"]
    return value


def make_site(root: Path) -> Path:
    """A site folder: an instrument ``falls`` in en and pt, a Portuguese words file, a QoS model."""
    site = root / "site"
    for part in ("instruments", "words", "qos"):
        (site / part).mkdir(parents=True)
    path = write_mini(site / "instruments", id="falls")
    data = _with_portuguese(yaml.safe_load(path.read_text()))
    data["languages"].append("pt")
    path.write_text(yaml.safe_dump(data, allow_unicode=True, sort_keys=False))
    english = (Path(WORDS_DIR) / "en.yaml").read_text(encoding="utf-8")
    (site / "words" / "pt.yaml").write_text(english.replace("code: en", "code: pt", 1).replace("Start", "Começar"))
    (site / "qos" / "ward.roqme").write_text(WARD_MODEL)
    return site


@pytest.fixture(autouse=True)
def _no_site_words_after():
    """A test's site languages end with it (the next configuration read sets them again)."""
    yield
    load_config(None, environ={})


def test_a_site_folder_gives_instruments_a_language_and_a_model(tmp_path):
    make_site(tmp_path)
    config = tmp_path / "config.yaml"
    config.write_text("site_dir: site\nlanguage: pt\ninstruments:\n  - {id: falls, qos_model: ward}\n")
    loaded = load_config(config, environ={})
    assert "pt" in languages() and START_LABEL["pt"] == "Começar"
    assert [(q.id, q.source, model) for q, model in configured_instruments(loaded)] == [
        ("falls", str(tmp_path / "site/instruments/falls.yaml"), str(tmp_path / "site/qos/ward.roqme")),
    ]
    config.write_text("site_dir: site\ninstruments: [falls, barthel]\n")
    battery = configured_instruments(load_config(config, environ={}))
    assert [q.id for q, _ in battery] == ["falls", "barthel"]
    assert battery[1][0].source == str(bundled_path("barthel.yaml"))  # the shipped Barthel
    model = load_kiosk_model(str(tmp_path / "site/qos/ward.roqme"))
    assert {"Calm", "Performance"} <= set(model.properties)  # its own and the imported CLARC's
    plain = tmp_path / "plain.yaml"
    plain.write_text("language: en\n")
    load_config(plain, environ={})
    assert "pt" not in languages()  # another configuration, without the site: the site's language is gone


def test_a_site_instrument_may_not_take_a_shipped_id_silently(tmp_path):
    site = make_site(tmp_path)
    mine = write_mini(site / "instruments", id="barthel")
    mine.rename(site / "instruments" / "ours.yaml")
    config = tmp_path / "config.yaml"
    message = refusal(config, "site_dir: site\ninstruments: [barthel]\n")
    assert message == (
        f"{site}/instruments/ours.yaml:1:5: id 'barthel' is a shipped instrument's: give this file its "
        "own id, or add `replaces: barthel` to use it instead of the shipped barthel on this site"
    )
    (site / "instruments" / "ours.yaml").write_text(
        "replaces: barthel\n" + (site / "instruments/ours.yaml").read_text()
    )
    battery = configured_instruments(load_config(config, environ={}))
    assert [(q.id, q.source) for q, _ in battery] == [("barthel", str(site / "instruments/ours.yaml"))]
    config.write_text("site_dir: site\n")  # the default instrument is the site's Barthel too
    assert configured_instruments(load_config(config, environ={}))[0][0].source == str(site / "instruments/ours.yaml")


@pytest.mark.parametrize(
    "first_line, message",
    [
        ("replaces: gds15\n", "ours.yaml:1:11: replaces: 'gds15' must be this file's own id ('falls2')"),
    ],
)
def test_replaces_names_the_files_own_shipped_id(tmp_path, first_line, message):
    site = make_site(tmp_path)
    mine = write_mini(site / "instruments", id="falls2")
    (site / "instruments" / "ours.yaml").write_text(first_line + mine.read_text())
    mine.unlink()
    assert refusal(tmp_path / "config.yaml", "site_dir: site\n").endswith(message)


def test_a_replaces_without_a_shipped_instrument_is_refused(tmp_path):
    site = make_site(tmp_path)
    mine = write_mini(site / "instruments", id="falls2")
    mine.write_text("replaces: falls2\n" + mine.read_text())
    assert refusal(tmp_path / "config.yaml", "site_dir: site\n") == (
        f"{mine}:1:11: replaces: no shipped instrument 'falls2' (shipped: barthel, gds15, lawton, sarc_f)"
    )


def test_every_problem_of_the_site_folder_is_one_positioned_line(tmp_path):
    site = make_site(tmp_path)
    (site / "words" / "es.yaml").write_text((Path(WORDS_DIR) / "es.yaml").read_text(encoding="utf-8"))
    (site / "words" / "pt.yaml").write_text((site / "words/pt.yaml").read_text().replace("code: pt", "code: br", 1))
    (site / "qos" / "bad.roqme").write_text('roqme Bad\nimport "nosuch.roqme"\n')
    lines = refusal(tmp_path / "config.yaml", "site_dir: site\n").splitlines()
    assert lines == [
        f"{site}/words/es.yaml:1:1: the kiosk ships es.yaml: a site's words files add new languages",
        f"{site}/words/pt.yaml:{_line_of(site / 'words/pt.yaml', 'code: br')}:9: "
        "language.code is 'br' but the file is pt.yaml",
        f"{site}/instruments/falls.yaml:{_line_of(site / 'instruments/falls.yaml', '- pt')}:3: "
        "language 'pt': the kiosk's screens have text in de, en, es, fr only",
        f"{site}/qos/bad.roqme:2:8: cannot import nosuch.roqme: no such model file",
    ]


def _line_of(path: Path, text: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), start=1) if text in line)


def test_site_dir_must_be_a_folder(tmp_path):
    assert refusal(tmp_path / "config.yaml", "language: en\nsite_dir: nowhere\n") == (
        f"{tmp_path}/config.yaml:2:1: site_dir: {tmp_path}/nowhere is not a folder (of instruments/, words/ and qos/)"
    )


def test_a_battery_entry_whose_model_is_missing_is_one_line(tmp_path):
    config = tmp_path / "config.yaml"
    config.write_text("instruments: [barthel, {id: gds15, qos_model: missing.roqme}]\n")
    assert refusal(config) == f"{config}:1:36: qos_model: no model file {tmp_path}/missing.roqme"
    done = kiosk("validate", "--config", str(config), cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stdout == f"{config}:1:36: qos_model: no model file {tmp_path}/missing.roqme\n"


def test_kiosk_validate_checks_a_site_folder_and_a_configuration(tmp_path):
    site = make_site(tmp_path)
    config = tmp_path / "config.yaml"
    config.write_text("site_dir: site\ninstruments: [falls, {id: barthel, qos_model: ward}]\n")
    done = kiosk("validate", "--site", str(site), "--config", str(config), cwd=tmp_path)
    assert (done.returncode, done.stdout) == (0, ""), done.stderr
    assert f"{site}: ok, instruments falls; languages pt; QoS models ward" in done.stderr
    assert f"{config}: ok, instruments falls, barthel" in done.stderr
    (site / "qos" / "ward.roqme").write_text(WARD_MODEL.replace("clarc.roqme", "clark.roqme"))
    done = kiosk("validate", "--site", str(site), cwd=tmp_path)
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert done.stdout == f"{site}/qos/ward.roqme:3:8: cannot import clark.roqme: no such model file\n"
