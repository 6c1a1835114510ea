"""``instruments:`` in the kiosk's configuration: a battery of shipped ids or files, each with an
optional RoQME model of its own, and one positioned message for every mistake."""

from __future__ import annotations

import pytest

from kiosk.config import ConfigError, InstrumentChoice, configured_instruments, load_config
from tests.kiosk.battery_instruments import write_mini
from tests.kiosk.configs import refusal


def test_a_battery_of_a_shipped_id_and_a_file_with_its_own_model(tmp_path):
    write_mini(tmp_path)
    path = tmp_path / "config.yaml"
    path.write_text("instruments:\n  - barthel\n  - {file: mini.yaml, qos_model: kiosk_pace}\n")
    config = load_config(path, environ={})
    assert config.instruments == (
        InstrumentChoice("barthel"),
        InstrumentChoice("mini.yaml", tmp_path / "mini.yaml", "kiosk_pace"),
    )
    assert [(q.id, model) for q, model in configured_instruments(config)] == [("barthel", None), ("mini", "kiosk_pace")]


def test_without_instruments_the_questionnaire_is_a_battery_of_one(tmp_path):
    path = tmp_path / "config.yaml"
    path.write_text("language: es\n")
    assert [q.id for q, _ in configured_instruments(load_config(path, environ={}))] == ["barthel"]


@pytest.mark.parametrize(
    "text, message",
    [
        (
            "questionnaire: b.yaml\ninstruments: [barthel]\n",
            "config.yaml:2:1: give either questionnaire: (one instrument) or instruments: (a battery), not both",
        ),
        ("instruments:\n  - barthel\n  - nosuch\n", "config.yaml:3:5: no shipped instrument 'nosuch'"),
        ("instruments: []\n", "config.yaml:1:1: instruments must be a list"),
        ("instruments:\n  - {id: barthel, qos_model: nomodel}\n", "config.yaml:2:19: no bundled model named 'nomodel'"),
        ("instruments:\n  - {id: barthel, file: x.yaml}\n", "config.yaml:2:5: an instrument is a shipped id, a file"),
    ],
)
def test_a_bad_battery_is_one_message_naming_file_line_and_column(tmp_path, text, message):
    assert refusal(tmp_path / "config.yaml", text).startswith(f"{tmp_path}/{message}")


def test_an_instrument_given_twice_is_refused(tmp_path):
    path = tmp_path / "config.yaml"
    path.write_text("instruments: [barthel, barthel]\n")
    with pytest.raises(ConfigError, match="'barthel' is given twice"):
        configured_instruments(load_config(path, environ={}))
