"""`kiosk replay` of a battery script: the instruments in order on one simulated clock, each
printed and stored as its own result, the visit's one trace; mistakes named by position."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from kiosk.commands.replay import main
from kiosk.commands.replay.script import ScriptError, load_battery_script
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.questionnaire.loading import bundled_path
from kiosk.store.database import Store
from tests.kiosk.battery_instruments import write_mini

DATA = Path(__file__).parent / "data"
ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture
def visit(tmp_path) -> Path:
    write_mini(tmp_path)
    (tmp_path / "config.yaml").write_text("instruments: [barthel, mini.yaml]\n")
    return Path(shutil.copy(DATA / "battery_visit.yaml", tmp_path / "visit.yaml"))


def test_a_battery_replays_each_instrument_and_stores_one_result_each(visit, tmp_path, capsys):
    data = tmp_path / "data"
    code = main([str(visit), "--config", str(tmp_path / "config.yaml"), "--data-dir", str(data)])
    out = capsys.readouterr().out
    assert code == 0
    assert out.index("barthel total") < out.index("mini total")
    assert "barthel total 100/100 complete, independent" in out and "mini total 5/15 complete, any" in out
    store = Store.open(data)
    try:
        sessions = [store.session(s.id) for s in store.sessions()]
        by_instrument = {s.questionnaire_id: s for s in sessions}
        assert set(by_instrument) == {"barthel", "mini"} and len(sessions) == 2
        barthel, mini = by_instrument["barthel"], by_instrument["mini"]
        assert barthel.status == mini.status == "finished" and barthel.patient_id == mini.patient_id == "P-0100"
        assert [(a.item_id, a.option, a.attempt) for a in mini.answers] == [("feeding", 2, 2), ("bathing", 1, 1)]
        # one visit: the second's contexts continue the first's in session time
        assert mini.trace[0]["t"] > barthel.trace[-1]["t"]
        assert {e.kind for e in mini.log} >= {"battery", "pause", "resume"}
    finally:
        store.close()


def test_the_json_names_each_instrument(visit, tmp_path, capsys):
    assert main([str(visit), "--config", str(tmp_path / "config.yaml"), "--json"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split('"instrument": "')[1].split('"')[0] for line in lines] == ["barthel", "mini"]


@pytest.mark.parametrize(
    "change, message",
    [
        (("  - id: mini\n", "  - id: nosuch\n"), ":20:9: no instrument 'nosuch' in the configuration or shipped"),
        (("    rest_after: 6\n", "    rest_after: 6\n    familiarisation: []\n"), ":22:5: only the first instrument"),
        (("      - {item: feeding, attempt: 2", "      - {item: toilet, attempt: 2"), ":24:16: question 1 of the"),
    ],
)
def test_a_bad_battery_script_names_the_position(visit, tmp_path, capsys, change, message):
    visit.write_text(visit.read_text().replace(*change))
    assert main([str(visit), "--config", str(tmp_path / "config.yaml")]) == 2
    assert capsys.readouterr().err.startswith(f"{visit}{message}")


def test_the_shipped_battery_recording_replays():
    folder = ROOT / "recordings/patients/batteries"
    config = folder / "cga.config.yaml"
    needed = [line.strip("- \n") for line in config.read_text().splitlines() if line.startswith("  - ")]
    assert all(bundled_path(f"{name}.yaml").is_file() for name in needed), needed  # shipped instruments
    script = load_battery_script(folder / "cga.yaml")
    assert [q.id for q in script.instruments] == needed
    assert main([str(folder / "cga.yaml"), "--config", str(config)]) == 0


def test_a_one_instrument_script_is_refused_a_battery_loader(tmp_path):
    with pytest.raises(ScriptError, match="a battery script gives questions per instrument"):
        path = tmp_path / "s.yaml"
        path.write_text("patient: P-01\nquestions: [{attempt: none}]\ninstruments: [{id: barthel, questions: []}]\n")
        load_battery_script(path, {"barthel": load_questionnaire()})
