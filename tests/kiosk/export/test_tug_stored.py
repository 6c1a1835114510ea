"""A Timed Up and Go stored with the visit and out of `kiosk results`: the row keeps times, phases,
quality flags and who decided (landmarks only when the site keeps them), and the stored times come
out as valid FHIR Observations in the --fhir Bundle and as rows beside the --csv file."""

from __future__ import annotations

import csv
import json
import sqlite3
from dataclasses import replace

from kiosk.commands.results import main as results_main
from kiosk.core.tug.families import generate
from kiosk.core.tug.landmarks import parse_pose_text
from kiosk.core.tug.step import TugResult, TugSettings
from kiosk.store.connection import DB_NAME
from kiosk.store.database import Store
from tests.kiosk.core.tug.stepping import go_of, run

from .standard import check_fhir


def camera_result(settings: TugSettings | None = None, seed: int = 11) -> TugResult:
    sequence, truth = generate("normal", seed)
    assert truth.onset_t is not None
    step, _, _ = run(sequence, go_of(sequence, truth.onset_t), settings)
    step.rate(get_up_go=3, walking_aid="stick")
    return step.decide("accepted", "dr-lee")


def stopwatch_result() -> TugResult:
    sequence, _ = generate("legs_cut", 4)
    step, _, _ = run(sequence, 1.0)
    return step.decide("stopwatch", "nurse-7", stopwatch_s=15.5)


def test_a_result_is_stored_and_read_back_whole(tmp_path):
    camera = camera_result(TugSettings(keep_landmarks=True))
    with Store.open(tmp_path) as store:
        first = store.tug.record("P-0042", camera, visit_id="v-1", at="2026-11-28T05:00:00+00:00")
        store.tug.record("P-0043", stopwatch_result(), at="2026-11-28T05:10:00+00:00")
    with Store.open(tmp_path, create=False) as store:
        stored = store.tug.all()
        assert [s.patient_id for s in stored] == ["P-0042", "P-0043"]
        assert [s.patient_id for s in store.tug.all("P-0043")] == ["P-0043"]
    back = stored[0]
    assert back.id == first and back.visit_id == "v-1"
    assert back.result == replace(camera, landmarks=None)  # landmarks come back as text
    assert back.landmarks_text is not None and camera.landmarks is not None
    assert len(parse_pose_text(back.landmarks_text, "stored").frames) == len(camera.landmarks.frames)
    assert stored[1].result.method == "stopwatch" and stored[1].result.body_cut_off
    assert stored[1].landmarks_text is None  # the site did not keep them
    with sqlite3.connect(tmp_path / DB_NAME) as db:
        columns = [row[1] for row in db.execute("PRAGMA table_info(tug_results)")]
    assert "landmarks" in columns and not any("video" in c or "frame" in c or "image" in c for c in columns)


def test_stored_times_go_out_as_valid_observations_and_csv(tmp_path, monkeypatch, capsys):
    config = tmp_path / "config.yaml"
    config.write_text("site: hosp-north\nkiosk_id: ward3-bed2\n", encoding="utf-8")
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    data = tmp_path / "data"
    camera = camera_result()
    sequence, _ = generate("normal", 12)
    rejected_step, _, _ = run(sequence, 0.5)
    with Store.open(data) as store:
        store.tug.record("P-0042", camera, at="2026-11-28T05:00:00+00:00")
        store.tug.record("P-0043", stopwatch_result(), at="2026-11-28T05:10:00+00:00")
        store.tug.record("P-0044", rejected_step.decide("rejected", "dr-lee"), at="2026-11-28T05:20:00+00:00")
        ids = [s.id for s in store.tug.all()]
    out, table = tmp_path / "all.json", tmp_path / "all.csv"
    assert results_main(["--data-dir", str(data), "--fhir", str(out), "--csv", str(table)]) == 0
    bundle = json.loads(out.read_text(encoding="utf-8"))
    check_fhir(bundle)
    tugs = [e for e in bundle["entry"] if e["resource"]["code"]["coding"][0]["code"] == "89423-8"]
    assert len(tugs) == 2  # the rejected one has no time
    by_method = {e["resource"]["method"]["coding"][0]["code"]: e["resource"] for e in tugs}
    cam, watch = by_method["camera"], by_method["stopwatch"]
    for resource in (cam, watch):
        check_fhir(resource)
    assert cam["identifier"][0]["value"] == f"hosp-north/ward3-bed2/{ids[0]}/tug"
    assert camera.total_s is not None and cam["valueQuantity"]["value"] == round(camera.total_s, 2)
    codes = [c["code"]["coding"][0]["code"] for c in cam["component"]]
    assert codes == ["sit_to_stand", "walk_out", "turn", "walk_back", "turn_and_sit", "get_up_go", "walking_aid"]
    assert cam["component"][5]["valueInteger"] == 3 and cam["component"][6]["valueString"] == "stick"
    assert cam["note"] == [{"text": "not above the site's threshold (13.5 s)"}] and "device" in cam
    assert watch["valueQuantity"]["value"] == 15.5 and "component" not in watch and "device" not in watch
    assert watch["note"] == [{"text": "above the site's threshold (13.5 s)"}]
    assert "interpretation" not in cam and "interpretation" not in watch  # not a diagnosis
    rows = list(csv.DictReader((tmp_path / "all-tug.csv").open(encoding="utf-8")))
    assert [(r["patient_id"], r["method"], r["measure"]) for r in rows][:2] == [
        ("P-0042", "camera", "total"),
        ("P-0042", "camera", "sit_to_stand"),
    ]
    assert rows[-1] == {
        "result_id": ids[1],
        "patient_id": "P-0043",
        "effective": "2026-11-28T05:10:00+00:00",
        "method": "stopwatch",
        "measure": "total",
        "seconds": "15.50",
        "accepted_by": "nurse-7",
    }
    assert "all-tug.csv" in capsys.readouterr().err
    assert results_main(["--data-dir", str(data)]) == 0
    listed = [line for line in capsys.readouterr().out.splitlines() if " tug " in line]
    assert [line.split()[0] for line in listed] == ids
    assert listed[1].endswith("stopwatch 15.5 s, above the site's threshold (13.5 s).")
    assert listed[2].endswith("rejected  No time taken (rejected).")
