"""`kiosk replay` of a scripted Timed Up and Go: the landmark file through the real TUG step and QoS
engine on the simulated clock (contexts, result, stored and exported), and one clear message for a
bad script."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from kiosk.commands.replay import main
from kiosk.commands.results import main as results_main
from kiosk.core.tug.families import generate
from kiosk.core.tug.landmarks import dump_pose_lines
from kiosk.store.database import Store

ROOT = Path(__file__).resolve().parents[3]
TUG = ROOT / "recordings/patients/tug"


@pytest.fixture(autouse=True)
def site(tmp_path, monkeypatch):
    config = tmp_path / "config.yaml"
    config.write_text("site: hosp-north\nkiosk_id: ward3-bed2\n", encoding="utf-8")
    monkeypatch.setenv("KIOSK_CONFIG", str(config))


def test_the_example_is_timed_with_its_contexts_stored_and_exported(tmp_path, capsys):
    data = tmp_path / "data"
    assert main([str(TUG / "normal.yaml"), "--json", "--data-dir", str(data)]) == 0
    out = json.loads(capsys.readouterr().out)
    tug = out["tug"]
    # the file's true total is 9.347 s (kiosk tug generate normal --seed 1)
    assert tug["total_s"] == pytest.approx(9.347, abs=0.2) and tug["method"] == "camera"
    assert tug["decision"] == "accepted" and tug["decided_by"] == "dr-lee" and tug["confirmed_by"] == "nurse-7"
    assert list(tug["phases"]) == ["sit_to_stand", "walk_out", "turn", "walk_back", "turn_and_sit"]
    assert tug["wording"].endswith("not above the site's threshold (13.5 s).")
    sets = [(k, v) for e in out["contexts"] for k, v in e["set"].items()]
    assert sets == [
        ("PersonIsNextToChair", True),
        ("PersonIsSeated", True),
        ("PersonGetsUp", True),
        ("PersonIsSeated", False),
        ("PersonGetsUp", False),
        ("PersonIsSeated", True),
        ("Scored", True),
    ]
    times = [e["t"] for e in out["contexts"]]
    assert times == sorted(times) and out["contexts"][1]["t"] == pytest.approx(0.834, abs=0.001)  # the file's go_t
    # the CLARC engine ran on them: O1 and O7 reinforce Performance and Interaction (0.5 before any evidence)
    assert out["metrics"]["Performance"] > 0.9 and out["metrics"]["Interaction"] > 0.9
    with Store.open(data, create=False) as store:
        [stored] = store.tug.all()
    assert stored.id == out["stored"] and stored.patient_id == "P-TUG-0001"
    assert stored.result.get_up_go == 1 and stored.landmarks_text is None
    bundle = tmp_path / "out.json"
    assert results_main(["--data-dir", str(data), "--fhir", str(bundle)]) == 0
    [observation] = [e["resource"] for e in json.loads(bundle.read_text(encoding="utf-8"))["entry"]]
    assert observation["valueQuantity"]["value"] == round(tug["total_s"], 2)


def test_legs_cut_off_the_stopwatch_time_is_taken(capsys):
    assert main([str(TUG / "legs_cut.yaml"), "--json"]) == 0
    tug = json.loads(capsys.readouterr().out)["tug"]
    assert tug["camera_total_s"] is None and tug["body_cut_off"] and any("legs" in r for r in tug["reasons"])
    assert (tug["total_s"], tug["method"]) == (14.2, "stopwatch")


def write(tmp_path: Path, text: str, frames: bool = True) -> Path:
    if frames:
        sequence, _ = generate("normal", 2)
        (tmp_path / "walk.jsonl").write_text("\n".join(dump_pose_lines(sequence)) + "\n", encoding="utf-8")
    path = tmp_path / "tug.yaml"
    path.write_text(text, encoding="utf-8")
    return path


BASE = "patient: P-T1\ntug:\n  landmarks: walk.jsonl\n  staff: nurse-7\n  decided_by: dr-lee\n"


@pytest.mark.parametrize(
    ("text", "frames", "message"),
    [
        (BASE + "  decision: maybe\n", True, "tug.yaml:6:"),
        (BASE + "  decision: stopwatch\n", True, "stopwatch_s"),
        (BASE + "  decision: accepted\n", False, "walk.jsonl cannot be read"),
        ("walk_up: true\n" + BASE + "  decision: accepted\n", True, "not offered at a walk-up visit"),
        (BASE + "  decision: accepted\n  go_t: 900\n", True, "after the last frame"),
    ],
)
def test_a_bad_script_is_one_message(tmp_path, capsys, text, frames, message):
    assert main([str(write(tmp_path, text, frames))]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f"{tmp_path / 'tug.yaml'}:") and message in err[0], err


def test_a_broken_landmark_file_names_its_line(tmp_path, capsys):
    path = write(tmp_path, BASE + "  decision: accepted\n")
    lines = (tmp_path / "walk.jsonl").read_text(encoding="utf-8").splitlines()
    lines[3] = '{"t": 0.1, "landmarks": [[0, 0, 0]]}'
    (tmp_path / "walk.jsonl").write_text("\n".join(lines) + "\n", encoding="utf-8")
    assert main([str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"{tmp_path / 'walk.jsonl'}:4:") and "\n" not in err


def test_the_site_threshold_and_landmarks_come_from_the_configuration(tmp_path, monkeypatch, capsys):
    config = tmp_path / "site.yaml"
    config.write_text("tug_threshold_s: 9\ntug_keep_landmarks: true\n", encoding="utf-8")
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    data = tmp_path / "data"
    assert main([str(TUG / "normal.yaml"), "--json", "--data-dir", str(data)]) == 0
    assert json.loads(capsys.readouterr().out)["tug"]["wording"].endswith("above the site's threshold (9 s).")
    with Store.open(data, create=False) as store:
        [stored] = store.tug.all()
    assert stored.result.threshold_s == 9 and stored.landmarks_text is not None
    config.write_text("tug_threshold_s: 200\n", encoding="utf-8")
    assert main([str(TUG / "normal.yaml")]) == 2
    err = capsys.readouterr().err.strip()
    assert f"{config}:1:" in err and "tug_threshold_s must be a number of seconds, 5 to 60" in err and "\n" not in err


def test_the_trace_replays_to_the_same_metrics(tmp_path, capsys):
    from qos import replay

    out = tmp_path / "tug.trace.yaml"
    assert main([str(TUG / "normal.yaml"), "--json", "--trace", str(out)]) == 0
    metrics = json.loads(capsys.readouterr().out)["metrics"]
    summary = replay(out)
    assert {name: m["last"] for name, m in summary["metrics"].items()} == pytest.approx(metrics)
    assert "PersonGetsUp: true" in out.read_text(encoding="utf-8")
