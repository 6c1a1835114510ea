"""FHIR R4 / CSV export and `kiosk results`, on sessions stored in a real SQLite database."""

from __future__ import annotations

import csv
import io
import json
import sqlite3
from pathlib import Path

import pytest

from kiosk.commands.replay import load_script, run_script
from kiosk.commands.results import main as results_main
from kiosk.core.channels import Channel
from kiosk.export import ITEM_WEIGHT, ExportError, csv_text, fhir_questionnaire, fhir_response, rescore
from kiosk.store.database import Store
from tests.kiosk.core.helpers import QUESTIONNAIRE, TIMING, make_rig
from tests.kiosk.export.standard import check_fhir

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture
def export_store(tmp_path):
    store = Store.open(tmp_path / "data")
    for name in ("barthel1", "barthel4"):
        run_script(load_script(ROOT / f"recordings/patients/{name}.yaml"), store=store)
    yield store
    store.close()


def by_patient(store: Store, patient: str):
    return next(store.session(s.id) for s in store.sessions() if s.patient_id == patient)


def test_the_fhir_questionnaire_puts_each_items_points_on_its_options():
    resource = fhir_questionnaire(QUESTIONNAIRE)
    assert resource["resourceType"] == "Questionnaire" and resource["code"][0]["code"] == "96762-0"
    items = {i["linkId"]: i for i in resource["item"]}
    weights = [[o["extension"][0]["valueDecimal"] for o in items[i.id]["answerOption"]] for i in QUESTIONNAIRE.items]
    assert weights == [[o.points for o in i.options] for i in QUESTIONNAIRE.items]
    assert all(
        o["extension"][0]["url"] == ITEM_WEIGHT for i in QUESTIONNAIRE.items for o in items[i.id]["answerOption"]
    )
    assert items["feeding"]["code"][0]["code"] == "83184-2"
    assert items["total"]["readOnly"] and "calculatedExpression" in items["total"]["extension"][0]["url"]
    check_fhir(resource)  # valid R4 for the official schema and fhir.resources


def test_the_fhir_response_recomputes_the_total(export_store):
    complete = fhir_response(QUESTIONNAIRE, by_patient(export_store, "TB-0001"))
    check_fhir(complete)
    assert complete["status"] == "completed"
    assert complete["subject"]["identifier"]["value"] == "TB-0001"
    total = [i for i in complete["item"] if i["linkId"] == "total"][0]["answer"][0]["valueInteger"]
    assert total == 100
    partial = fhir_response(QUESTIONNAIRE, by_patient(export_store, "TB-0004"))
    check_fhir(partial)
    answered = [i for i in partial["item"] if "answer" in i and i["linkId"] != "total"]
    assert len(answered) == 8
    assert [i for i in partial["item"] if i["linkId"] == "total"] == []  # no partial total, not even an empty item


def test_a_tampered_stored_total_is_ignored_and_tampered_points_are_refused(export_store):
    db = sqlite3.connect(export_store.path)
    with db:
        db.execute("UPDATE sessions SET total = 3")
    stored = by_patient(export_store, "TB-0001")
    assert rescore(QUESTIONNAIRE, stored).total == 100
    with db:
        db.execute("UPDATE answers SET points = 15 WHERE item_id = 'feeding'")
    with pytest.raises(ExportError, match="feeding option 3 is worth 10 points in barthel, but 15 were stored"):
        fhir_response(QUESTIONNAIRE, by_patient(export_store, "TB-0001"))


def test_csv_has_a_row_per_item_and_a_recomputed_total(export_store):
    stored = by_patient(export_store, "TB-0004")
    rows = list(csv.DictReader(io.StringIO(csv_text(QUESTIONNAIRE, [stored]))))
    assert [r["item"] for r in rows] == [i.id for i in QUESTIONNAIRE.items] + ["total"]
    grooming = rows[2]
    assert (grooming["option"], grooming["label"]) == ("", "not answered")
    label = rows[-1]["label"]
    assert rows[-1]["points"] == "" and label.startswith("No total: not answered: Grooming")
    assert ", Bladder" in label and label.endswith(" (65 points from 8 of 10 items)")
    assert rows[0]["channel"] == "voice" and rows[0]["attempt"] == "1"


def test_kiosk_results_lists_shows_and_exports_owner_only(export_store, tmp_path, capsys):
    data = str(export_store.path.parent)
    assert results_main(["--data-dir", data]) == 0
    listing = capsys.readouterr().out.splitlines()
    assert len(listing) == 2 and all("finished" in line for line in listing)
    assert any(line.endswith("No total: 2 of 10 questions not answered") for line in listing), listing
    session_id = by_patient(export_store, "TB-0004").id
    fhir, table = tmp_path / "r.json", tmp_path / "r.csv"
    table.write_text("old export\n")
    table.chmod(0o644)  # an export written over an old world-readable file becomes owner-only
    assert results_main([session_id[:6], "--data-dir", data, "--fhir", str(fhir), "--csv", str(table)]) == 0
    shown = capsys.readouterr().out
    (line,) = [x for x in shown.splitlines() if x.startswith("No total")]
    assert line.startswith("No total: not answered: Grooming") and ", Bladder" in line
    assert line.endswith("(the answered ones add up to 65)")
    bundle = json.loads(fhir.read_text())
    check_fhir(bundle)
    assert [e["resource"]["resourceType"] for e in bundle["entry"]] == [
        "Questionnaire",
        "Device",
        "QuestionnaireResponse",
    ]
    assert fhir.stat().st_mode & 0o777 == 0o600 and table.stat().st_mode & 0o777 == 0o600


def test_kiosk_results_for_an_unknown_session_is_exit_2(export_store, capsys):
    assert results_main(["zzz", "--data-dir", str(export_store.path.parent)]) == 2
    assert capsys.readouterr().err.strip() == "kiosk results: no session 'zzz'"


def test_the_configured_band_set_interprets_the_session_its_export_and_kiosk_results(tmp_path, monkeypatch, capsys):
    spanish = QUESTIONNAIRE.with_band_set("spanish")
    store = Store.open(tmp_path / "data")
    run_script(load_script(ROOT / "recordings/patients/barthel2.yaml"), spanish, store=store)  # 75 points
    stored = by_patient(store, "TB-0002")
    db = sqlite3.connect(store.path)
    assert db.execute("SELECT total, band FROM sessions").fetchall() == [(75, "mild")]  # Shah: moderate
    store.close()
    totals = [list(csv.DictReader(io.StringIO(csv_text(q, [stored]))))[-1] for q in (QUESTIONNAIRE, spanish)]
    assert [(t["item"], t["points"], t["label"], t["band_set"]) for t in totals] == [
        ("total", "75", "moderate", "shah"),
        ("total", "75", "mild", "spanish"),
    ]

    config = tmp_path / "config.yaml"
    config.write_text("bands: spanish\n")
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    table = tmp_path / "r.csv"
    assert results_main([stored.id, "--data-dir", str(tmp_path / "data"), "--csv", str(table)]) == 0
    assert (
        "total 75/100 (complete); Mild dependence (bands: spanish, Spanish clinical practice (unconfirmed source))"
    ) in capsys.readouterr().out
    assert list(csv.DictReader(table.open()))[-1]["band_set"] == "spanish"
    # the session keeps the band set it was recorded with, whatever the configuration says today
    config.write_text("bands: shah\n")
    assert results_main([stored.id, "--data-dir", str(tmp_path / "data")]) == 0
    assert "Mild dependence (bands: spanish" in capsys.readouterr().out


def test_practice_outcomes_are_in_kiosk_results_and_the_csv_but_not_in_fhir(tmp_path, capsys):
    store = Store.open(tmp_path / "data")
    rig = make_rig(familiarisation=True, store=store)
    rig.session.set_voice_out_available(False)  # the hearing check is skipped
    rig.at(5)
    rig.session.start()
    rig.at(8)
    rig.answer(2, Channel.REMOTE)  # "No" where "Yes" was asked for
    # after the feedback gap, the selecting check gets no answer
    rig.run_until(8 + TIMING["between_questions_s"] + 2 * TIMING["attempt_window_s"])
    assert rig.session.phase.value == "explanation"
    session_id = rig.session.id
    store.close()

    table = tmp_path / "r.csv"
    assert results_main([session_id, "--data-dir", str(tmp_path / "data"), "--csv", str(table)]) == 0
    assert (
        "practice: hearing: skipped (no voice out); reading: wrong (chose No); selecting: not answered"
        in capsys.readouterr().out.splitlines()
    )
    rows = list(csv.DictReader(table.open()))
    practice = [
        (r["item"], r["checks"], r["option"], r["label"], r["channel"], r["points"])
        for r in rows
        if r["kind"] == "practice"
    ]
    assert practice == [
        ("practice_hear", "hear", "", "skipped (no voice out)", "", ""),
        ("practice_read", "read", "2", "wrong (chose No)", "remote", ""),
        ("practice_select", "select", "", "not answered", "", ""),
    ]
    assert [r["kind"] for r in rows] == ["practice"] * 3 + ["item"] * 10 + ["total"]
    assert rows[-1]["points"] == "" and rows[-1]["label"].endswith(
        " (0 points from 0 of 10 items)"
    )  # practice never scores

    with Store.open(tmp_path / "data") as reopened:
        response = fhir_response(QUESTIONNAIRE, reopened.session(session_id))
    check_fhir(response)
    assert "item" not in response  # nothing answered: no item at all (unanswered items are left out, as SDC does)
    assert "practice" not in json.dumps(response)


def test_kiosk_results_says_when_a_session_had_no_practice(export_store, capsys):
    stored = by_patient(export_store, "TB-0001")
    assert results_main([stored.id, "--data-dir", str(export_store.path.parent)]) == 0
    assert "practice: none (no practice questions in this session)" in capsys.readouterr().out


@pytest.mark.parametrize("option", ["--csv", "--fhir", "--fhir-questionnaire"])
def test_kiosk_results_to_an_unwritable_path_is_one_line_and_exit_2(export_store, tmp_path, capsys, option):
    target = tmp_path / "no" / "such" / "out"
    session_id = by_patient(export_store, "TB-0004").id
    assert results_main([session_id, "--data-dir", str(export_store.path.parent), option, str(target)]) == 2
    assert capsys.readouterr().err == f"kiosk results: cannot write {target}: No such file or directory\n"


def test_kiosk_results_csv_of_all_sessions_to_a_directory_is_one_line_and_exit_2(export_store, tmp_path, capsys):
    assert results_main(["--data-dir", str(export_store.path.parent), "--csv", str(tmp_path)]) == 2
    assert capsys.readouterr().err == f"kiosk results: cannot write {tmp_path}: Is a directory\n"
