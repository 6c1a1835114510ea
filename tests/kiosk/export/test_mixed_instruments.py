"""`kiosk replay` and `kiosk results` on a kiosk whose store holds results of two instruments (the
Barthel and a four-item mood scale, tests/instruments/mood4.yaml): the listing and the shown
session name the instrument, the FHIR Bundle carries a Questionnaire per instrument and language
(each under its own canonical URL), the long CSV names the instrument on every row and the wide
CSV is one table per instrument (issue 26, part 5)."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from kiosk.commands.replay import main as replay_main
from kiosk.commands.results import main as results_main
from kiosk.export import ExportError
from kiosk.export.captured import wide_csv_of, wide_csv_tables
from kiosk.store.database import Store
from tests.instruments import MOOD4, MOOD4_PATIENT

from .conftest import ROOT
from .standard import check_fhir

SITE = "site: hosp-north\nkiosk_id: ward3-bed2\nfhir: {questionnaire_url: 'https://hosp-north.example/fhir/Questionnaire/{id}'}\n"


@pytest.fixture(scope="module")
def mixed(tmp_path_factory) -> tuple[Path, Path]:
    """(data directory, the mood scale's config): two Barthel and two mood-scale sessions stored
    by real `kiosk replay --data-dir` runs, the mood scale's through a config naming its file."""
    base = tmp_path_factory.mktemp("mixed")
    data = base / "data"
    barthel, mood = base / "barthel.yaml", base / "mood.yaml"
    barthel.write_text(SITE, encoding="utf-8")
    mood.write_text(SITE + f"questionnaire: {MOOD4}\n", encoding="utf-8")
    patients = ROOT / "recordings/patients"
    scripts = [patients / "barthel1.yaml", patients / "spanish_voice.yaml"]
    assert replay_main([*map(str, scripts), "--config", str(barthel), "--data-dir", str(data)]) == 0
    second = base / "mood_patient2.yaml"
    second.write_text(MOOD4_PATIENT.read_text(encoding="utf-8").replace("TB-0900", "TB-0901"), encoding="utf-8")
    assert replay_main([str(MOOD4_PATIENT), str(second), "--config", str(mood), "--data-dir", str(data)]) == 0
    return data, barthel


def test_a_replay_summary_names_the_instrument_and_its_own_total(tmp_path, capsys):
    config = tmp_path / "config.yaml"
    config.write_text(f"questionnaire: {MOOD4}\n", encoding="utf-8")
    assert replay_main([str(MOOD4_PATIENT), "--config", str(config)]) == 0
    out = capsys.readouterr().out
    assert "mood4 total 20/25 complete, suggests" in out and "Barthel" not in out


def test_the_listing_and_a_shown_session_name_each_instrument(mixed, monkeypatch, capsys):
    data, config = mixed
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    capsys.readouterr()  # what the fixture's replays printed
    assert results_main(["--data-dir", str(data)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert sorted(line.split()[3] for line in lines) == ["barthel", "barthel", "mood4", "mood4"]
    with Store.open(data, create=False) as store:
        (mood,) = [s for s in store.sessions() if s.patient_id == "TB-0900"]
    assert results_main([mood.id, "--data-dir", str(data)]) == 0
    shown = capsys.readouterr().out
    assert "questionnaire mood4 2" in shown and "total 20/25 (complete); Suggests depression" in shown
    assert "energy" in shown and "feeding" not in shown


def test_one_bundle_a_questionnaire_per_instrument_and_language(mixed, tmp_path, monkeypatch, capsys):
    data, config = mixed
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    capsys.readouterr()  # what the fixture's replays printed
    out = tmp_path / "all.json"
    assert results_main(["--data-dir", str(data), "--fhir", str(out)]) == 0
    bundle = json.loads(out.read_text(encoding="utf-8"))
    check_fhir(bundle)
    resources = [e["resource"] for e in bundle["entry"]]
    urls = sorted(r["url"] for r in resources if r["resourceType"] == "Questionnaire")
    base = "https://hosp-north.example/fhir/Questionnaire/"
    assert urls == [base + "barthel-en", base + "barthel-es", base + "mood4-en"]
    totals = {
        r["code"]["coding"][0]["code"]: r for r in resources if r["resourceType"] == "Observation"
    }  # both mood patients score 20: one code per instrument is enough to compare
    assert totals["mood4-total"]["valueQuantity"]["value"] == 20
    assert totals["mood4-total"]["interpretation"][0]["coding"][0]["system"].endswith(":mood4:screen")
    assert totals["96761-2"]["interpretation"][0]["coding"][0]["system"].endswith(":barthel:shah")
    responses = [r for r in resources if r["resourceType"] == "QuestionnaireResponse"]
    assert sorted(r["questionnaire"].split("|")[0] for r in responses) == [
        base + "barthel-en",
        base + "barthel-es",
        base + "mood4-en",
        base + "mood4-en",
    ]


def test_csv_long_names_the_instrument_and_wide_is_one_table_each(mixed, tmp_path, monkeypatch, capsys):
    data, config = mixed
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    capsys.readouterr()  # what the fixture's replays printed
    long, wide = tmp_path / "long.csv", tmp_path / "wide.csv"
    assert results_main(["--data-dir", str(data), "--csv", str(long), "--csv-wide", str(wide)]) == 0
    told = capsys.readouterr().err
    assert not wide.exists()
    tables = {qid: tmp_path / f"wide-{qid}.csv" for qid in ("barthel", "mood4")}
    assert f"{tables['barthel']}, {tables['mood4']}" in told
    mood = pd.read_csv(tables["mood4"], dtype=str)
    barthel = pd.read_csv(tables["barthel"], dtype=str)
    assert len(mood) == 2 and len(barthel) == 2
    assert set(mood["questionnaire"]) == {"mood4"} and set(barthel["questionnaire"]) == {"barthel"}
    assert "energy_points" in mood.columns and not any(c.startswith("feeding") for c in mood.columns)
    assert "feeding_points" in barthel.columns and not any(c.startswith("energy") for c in barthel.columns)
    assert list(mood["total"]) == ["20", "20"] and list(mood["band"]) == ["suggests", "suggests"]
    assert all(tables[q].stat().st_mode & 0o777 == 0o600 for q in tables)
    rows = pd.read_csv(long, dtype=str)
    items = rows[rows["kind"] == "item"]
    assert set(items[items["questionnaire"] == "mood4"]["item"]) == {"satisfied", "bored", "energy", "hopeful"}
    assert "feeding" in set(items[items["questionnaire"] == "barthel"]["item"])


def test_one_wide_table_of_several_instruments_is_refused_by_name(mixed):
    data, _ = mixed
    with Store.open(data, create=False) as store:
        stored = [store.session(s.id) for s in store.sessions()]
    assert list(wide_csv_tables(stored)) in (["barthel", "mood4"], ["mood4", "barthel"])
    with pytest.raises(ExportError, match=r"ran 2 instruments \((barthel, mood4|mood4, barthel)\)"):
        wide_csv_of(stored)
    assert wide_csv_of([s for s in stored if s.questionnaire_id == "mood4"]).count("\n") == 3
