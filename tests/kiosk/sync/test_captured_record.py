"""A result says what was asked and where, whatever changes after it was recorded: real `kiosk
replay` and `kiosk results` processes, and a real `kiosk station` process the replays deliver to.

A session is recorded at site A (kiosk-a) on version 1 of a questionnaire file. Then the file is
edited (a question's text changed, two of its options swapped) and the configuration names site B
(laptop-7, other FHIR systems). `kiosk results --fhir/--csv` then gives, byte for byte, the exports
made at once (same identifier, questionnaire canonical and version, texts and displays), exit 0;
the station describes the session with the kiosk's identity and definition too. A session
recorded after the edit, at B, is described with the edited file, at the kiosk and at the station."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from kiosk.core.questionnaire import bundled_path
from station import auth, db
from tests.kiosk.sync.test_station_e2e import free_port
from tests.station.conftest import PASSWORDS, start_station
from tests.station.helpers import Staff

ROOT = Path(__file__).resolve().parents[3]
ORIGINAL_TEXT = "Feeding: how do you manage eating?"
EDITED_TEXT = "Feeding (revised wording): how do you eat your meals?"

pytestmark = pytest.mark.slow


def _config(path: Path, site: str, kiosk: str, questionnaire: Path, station: str, token: str) -> Path:
    path.write_text(
        f"site: {site}\nkiosk_id: {kiosk}\nquestionnaire: {questionnaire}\n"
        f"fhir: {{patient_system: 'https://{site}.example/sid/patient', "
        f"questionnaire_url: 'https://{site}.example/fhir/Questionnaire/barthel', "
        f"identifier_system: 'https://{site}.example/sid/result', device_system: 'https://{site}.example/sid/kiosk'}}\n"
        f"station: {{url: '{station}', token: '{token}', kiosk_id: {kiosk}}}\n",
        encoding="utf-8",
    )
    return path


def _edit(questionnaire: Path) -> None:
    """Change the feeding question's English text and swap its first two options."""
    text = questionnaire.read_text(encoding="utf-8")
    assert text.count(ORIGINAL_TEXT) == 1
    text = text.replace(ORIGINAL_TEXT, EDITED_TEXT)
    start = text.index("  - id: feeding")
    first = text.index("      - points: 0\n", start)
    second = text.index("      - points: 5\n", first)
    third = text.index("      - points: 10\n", second)
    text = text[:first] + text[second:third] + text[first:second] + text[third:]
    questionnaire.write_text(text, encoding="utf-8")


def _kiosk(*args: str, config: Path) -> subprocess.CompletedProcess:
    env = os.environ | {"KIOSK_CONFIG": str(config)}
    return subprocess.run(
        [sys.executable, "-m", "kiosk", *args], capture_output=True, text=True, cwd=ROOT, env=env, timeout=300
    )


def _response(bundle: dict) -> dict:
    (response,) = [e["resource"] for e in bundle["entry"] if e["resource"]["resourceType"] == "QuestionnaireResponse"]
    return response


def _words(response: dict) -> list:
    """What a response says: item texts and answer displays, in order."""
    return [
        (i["linkId"], i.get("text"), [a.get("valueCoding", {}).get("display") for a in i.get("answer", [])])
        for i in response["item"]
    ]


def test_a_result_keeps_its_identity_and_questionnaire_after_the_file_and_the_config_change(tmp_path):
    db_url = db.sqlite_url(tmp_path / "station")
    engine = db.open_database(db_url)
    tokens = {name: auth.add_kiosk(engine, name) for name in ("kiosk-a", "laptop-7")}
    auth.add_user(engine, "dr.lopez", "doctor", PASSWORDS["doctor"])
    engine.dispose()
    port = free_port()
    url = f"http://127.0.0.1:{port}"
    station = start_station(db_url, tmp_path / "station.log", port)
    staff = Staff(station.url)
    data, questionnaire = tmp_path / "data", tmp_path / "barthel.yaml"
    questionnaire.write_text(bundled_path().read_text(encoding="utf-8"), encoding="utf-8")
    site_a = _config(tmp_path / "a.yaml", "sitea", "kiosk-a", questionnaire, url, tokens["kiosk-a"])
    site_b = _config(tmp_path / "b.yaml", "siteb", "laptop-7", questionnaire, url, tokens["laptop-7"])
    try:
        recorded = _kiosk(
            "replay", str(ROOT / "recordings/patients/barthel5.yaml"), "--data-dir", str(data), config=site_a
        )
        assert recorded.returncode == 0, recorded.stderr
        at_once = _kiosk(
            "results",
            "--data-dir",
            str(data),
            "--fhir",
            str(tmp_path / "once.json"),
            "--csv",
            str(tmp_path / "once.csv"),
            config=site_a,
        )
        assert at_once.returncode == 0, at_once.stderr
        first = _response(json.loads((tmp_path / "once.json").read_text(encoding="utf-8")))
        session = first["identifier"]["value"].rsplit("/", 1)[1]
        assert first["identifier"] == {
            "system": "https://sitea.example/sid/result",
            "value": f"sitea/kiosk-a/{session}",
        }
        assert first["questionnaire"].startswith("https://sitea.example/fhir/Questionnaire/barthel-en|")
        assert next(i for i in first["item"] if i["linkId"] == "feeding")["text"] == ORIGINAL_TEXT
        station_first = staff.http.get(f"/sessions/{session}/export.json")
        assert station_first.status_code == 200, station_first.text
        # unreviewed, the station's Bundle is the kiosk's, entry for entry: one code path
        assert station_first.json() == json.loads((tmp_path / "once.json").read_text(encoding="utf-8"))

        _edit(questionnaire)  # version 1 is gone from disk, and the site is now B
        later = _kiosk(
            "results",
            "--data-dir",
            str(data),
            "--fhir",
            str(tmp_path / "later.json"),
            "--csv",
            str(tmp_path / "later.csv"),
            config=site_b,
        )
        assert later.returncode == 0, later.stderr
        assert (tmp_path / "later.json").read_bytes() == (tmp_path / "once.json").read_bytes()
        assert (tmp_path / "later.csv").read_bytes() == (tmp_path / "once.csv").read_bytes()
        shown = _kiosk("results", session, "--data-dir", str(data), config=site_b)
        assert shown.returncode == 0 and "recorded at sitea/kiosk-a" in shown.stdout, shown.stderr
        # even a file broken since then does not stop the recorded session's export
        good = questionnaire.read_text(encoding="utf-8")
        questionnaire.write_text(good.replace("points: 10", "points: 11", 1), encoding="utf-8")
        broken = _kiosk("results", "--data-dir", str(data), "--fhir", str(tmp_path / "broken.json"), config=site_b)
        assert broken.returncode == 0, broken.stderr
        assert (tmp_path / "broken.json").read_bytes() == (tmp_path / "once.json").read_bytes()
        questionnaire.write_text(good, encoding="utf-8")

        # the station describes it as the kiosk does: the kiosk's identity, canonical, texts and displays
        station_later = staff.http.get(f"/sessions/{session}/export.json").json()
        assert station_later == station_first.json()
        for key in ("identifier", "questionnaire", "subject"):
            assert _response(station_later)[key] == first[key], key
        assert _words(_response(station_later)) == _words(first)
        page = staff.http.get(f"/sessions/{session}").text
        assert ORIGINAL_TEXT in page and EDITED_TEXT not in page

        # a session recorded after the edit, at B: the edited file, B's identity, at both ends
        edited = _kiosk(
            "replay", str(ROOT / "recordings/patients/barthel5.yaml"), "--data-dir", str(data), config=site_b
        )
        assert edited.returncode == 0, edited.stderr
        both = _kiosk(
            "results",
            "--data-dir",
            str(data),
            "--fhir",
            str(tmp_path / "both.json"),
            "--csv",
            str(tmp_path / "both.csv"),
            config=site_b,
        )
        assert both.returncode == 0, both.stderr
        bundle = json.loads((tmp_path / "both.json").read_text(encoding="utf-8"))
        responses = {
            r["identifier"]["value"].split("/")[0]: r
            for r in (
                e["resource"] for e in bundle["entry"] if e["resource"]["resourceType"] == "QuestionnaireResponse"
            )
        }
        assert set(responses) == {"sitea", "siteb"}
        table = list(csv.DictReader((tmp_path / "both.csv").open(encoding="utf-8")))
        assert {(r["kiosk_id"], r["questionnaire_version"]) for r in table} == {
            ("K:kiosk-a", responses["sitea"]["questionnaire"].split("|")[1]),
            ("K:laptop-7", responses["siteb"]["questionnaire"].split("|")[1]),
        }
        newer = responses["siteb"]
        assert newer["questionnaire"].split("|")[1] != first["questionnaire"].split("|")[1]  # another version
        assert next(i for i in newer["item"] if i["linkId"] == "feeding")["text"] == EDITED_TEXT
        station_newer = staff.http.get(f"/sessions/{newer['identifier']['value'].rsplit('/', 1)[1]}/export.json")
        assert station_newer.status_code == 200, station_newer.text
        assert _words(_response(station_newer.json())) == _words(newer)
        assert _response(station_newer.json())["identifier"] == newer["identifier"]
    finally:
        staff.http.close()
        station.stop()
    assert "Traceback" not in (tmp_path / "station.log").read_text()
