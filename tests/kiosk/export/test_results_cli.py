"""`kiosk results` exports of several or all stored sessions, as a hospital would send them."""

from __future__ import annotations

import json

import pandas as pd

from kiosk.commands.results import main as results_main
from kiosk.export import questionnaire_version
from tests.kiosk.core.helpers import QUESTIONNAIRE

from .standard import check_fhir


def _configure(tmp_path, monkeypatch) -> None:
    config = tmp_path / "config.yaml"
    config.write_text(
        "site: hosp-north\nkiosk_id: ward3-bed2\n"
        "fhir: {questionnaire_url: 'https://hosp-north.example/fhir/Questionnaire/barthel'}\n",
        encoding="utf-8",
    )
    monkeypatch.setenv("KIOSK_CONFIG", str(config))


def test_all_sessions_as_one_valid_transaction_bundle_with_the_site_identity(
    replay_dir, replayed, tmp_path, monkeypatch, capsys
):
    _configure(tmp_path, monkeypatch)
    out = tmp_path / "all.json"
    assert results_main(["--data-dir", str(replay_dir), "--fhir", str(out)]) == 0
    assert len(capsys.readouterr().out.splitlines()) == len(replayed)  # still lists the sessions
    bundle = json.loads(out.read_text(encoding="utf-8"))
    check_fhir(bundle)
    responses = [e for e in bundle["entry"] if e["resource"]["resourceType"] == "QuestionnaireResponse"]
    assert {e["resource"]["identifier"]["value"] for e in responses} == {
        f"hosp-north/ward3-bed2/{s.id}" for s in replayed.values()
    }
    conditions = {e["resource"]["resourceType"]: e["request"]["ifNoneExist"].split("=")[0] for e in bundle["entry"]}
    assert all(e["request"]["method"] == "POST" for e in bundle["entry"])  # nothing signed off on a kiosk
    assert conditions == {
        "Questionnaire": "url",
        "Device": "identifier",
        "QuestionnaireResponse": "identifier",
        "Observation": "identifier",
    }
    totals = [e for e in bundle["entry"] if e["resource"]["resourceType"] == "Observation"]
    complete = [s for s in replayed.values() if not s.not_answered]
    assert len(totals) == len(complete)
    assert out.stat().st_mode & 0o777 == 0o600


def test_chosen_sessions_and_the_questionnaire_in_one_language(replay_dir, replayed, tmp_path, monkeypatch, capsys):
    _configure(tmp_path, monkeypatch)
    spanish, french = replayed["P-ES-0001"], replayed["P-FR-0003"]
    bundle_file, questionnaire_file = tmp_path / "two.json", tmp_path / "q-es.json"
    assert (
        results_main(
            [
                spanish.id,
                french.id[:8],
                "--data-dir",
                str(replay_dir),
                "--fhir",
                str(bundle_file),
                "--fhir-questionnaire",
                str(questionnaire_file),
                "--language",
                "es",
            ]
        )
        == 0
    )
    shown = capsys.readouterr().out
    assert f"session {spanish.id}" in shown and f"session {french.id}" in shown
    bundle = json.loads(bundle_file.read_text(encoding="utf-8"))
    assert [e["resource"]["resourceType"] for e in bundle["entry"]] == [
        "Questionnaire",
        "Questionnaire",
        "Device",
        "QuestionnaireResponse",
        "Observation",
        "QuestionnaireResponse",
    ]
    questionnaire = json.loads(questionnaire_file.read_text(encoding="utf-8"))
    check_fhir(questionnaire)
    assert (questionnaire["url"], questionnaire["version"], questionnaire["language"]) == (
        "https://hosp-north.example/fhir/Questionnaire/barthel-es",
        questionnaire_version(QUESTIONNAIRE),
        "es",
    )
    assert bundle["entry"][0]["resource"] == {k: v for k, v in questionnaire.items() if k != "id"}


def test_a_bad_site_setting_is_one_line_and_exit_2(replay_dir, tmp_path, monkeypatch, capsys):
    config = tmp_path / "config.yaml"
    config.write_text("kiosk_id: ward 3\n", encoding="utf-8")
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    assert results_main(["--data-dir", str(replay_dir), "--fhir", str(tmp_path / "x.json")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"kiosk results: {config}:1:1: kiosk_id must be") and err.count("\n") == 1
    assert not (tmp_path / "x.json").exists()


def test_sessions_from_kiosk_replay_are_labelled_test_data(tmp_path, monkeypatch, capsys):
    from kiosk.commands.replay import main as replay_main

    from .conftest import ROOT

    _configure(tmp_path, monkeypatch)
    data = tmp_path / "data"
    assert replay_main([str(ROOT / "recordings/patients/barthel1.yaml"), "--data-dir", str(data)]) == 0
    out, table = tmp_path / "replayed.json", tmp_path / "replayed.csv"
    assert results_main(["--data-dir", str(data), "--fhir", str(out), "--csv-wide", str(table)]) == 0
    bundle = json.loads(out.read_text(encoding="utf-8"))
    check_fhir(bundle)
    labelled = {e["resource"]["resourceType"]: e["resource"].get("meta", {}).get("security") for e in bundle["entry"]}
    test_data = [
        {"system": "http://terminology.hl7.org/CodeSystem/v3-ActReason", "code": "HTEST", "display": "test health data"}
    ]
    assert labelled["QuestionnaireResponse"] == labelled["Observation"] == test_data
    assert labelled["Questionnaire"] is None and labelled["Device"] is None
    frame = pd.read_csv(table)
    assert frame["simulated"].tolist() == [True]


def test_an_empty_store_exports_an_empty_but_valid_bundle(tmp_path, monkeypatch, capsys):
    from kiosk.store.database import Store

    _configure(tmp_path, monkeypatch)
    Store.open(tmp_path / "data").close()
    out = tmp_path / "none.json"
    assert results_main(["--data-dir", str(tmp_path / "data"), "--fhir", str(out)]) == 0
    assert capsys.readouterr().err == "no sessions stored\n"
    bundle = json.loads(out.read_text(encoding="utf-8"))
    check_fhir(bundle)
    assert bundle == {"resourceType": "Bundle", "type": "transaction"}


def test_a_batterys_questionnaires_are_one_bundle_of_every_instrument(tmp_path, monkeypatch, capsys):
    config = tmp_path / "battery.yaml"
    from kiosk.store.database import Store

    Store.open(tmp_path / "data").close()  # a kiosk's data directory, no session yet
    config.write_text(f"data_dir: {tmp_path / 'data'}\ninstruments: [barthel, gds15, lawton]\n")
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    out = tmp_path / "questionnaires.json"
    assert results_main(["--fhir-questionnaire", str(out)]) == 0
    bundle = json.loads(out.read_text())
    check_fhir(bundle)
    urls = [e["resource"]["url"] for e in bundle["entry"]]
    for instrument, languages in {"barthel": "en es fr de", "gds15": "en es fr de", "lawton": "en es fr"}.items():
        assert sum(u.rsplit(":", 1)[1].startswith(f"{instrument}-") for u in urls) == len(languages.split()), urls
    assert results_main(["--fhir-questionnaire", str(out), "--language", "fr"]) == 0
    assert len(json.loads(out.read_text())["entry"]) == 3  # one French Questionnaire per instrument
    # German: the Lawton has no German text, and nothing is written half
    out.unlink()
    assert results_main(["--fhir-questionnaire", str(out), "--language", "de"]) == 2
    assert "lawton has no such translation" in capsys.readouterr().err and not out.exists()
