"""Nothing a kiosk sends is run in the serving process (issue 37, part 4), with a real station
process over HTTP: a session whose captured definition has a total formula the station does not
know is shown without a total and waits for a doctor's approval; once approved, its formula runs
in the formula process -- one with a catastrophic regular expression is cut off there, while
``/healthz`` keeps answering and SIGTERM still stops the station."""

from __future__ import annotations

import threading
import uuid
from pathlib import Path

import httpx
import pytest

from kiosk.core.questionnaire import bundled_path, load_questionnaire
from kiosk.core.questionnaire.definition import canonical, digest
from tests.station.conftest import PATIENCE_S, make_ward
from tests.station.helpers import KioskClient, Row, Staff

pytestmark = pytest.mark.slow

#: the formula budget the station is started with: long enough that /healthz is asked while the
#: formula runs even on a loaded machine (the default is 2 s)
BUDGET_S = 20
#: exponential backtracking in Python's re: (a+)+$ against many a's and a final '!'
EVIL = "iif('" + "a" * 34 + "!'.matches('^(a+)+$'), 1, 0)"


def definition_with(expression: str) -> dict:
    definition = canonical(load_questionnaire(bundled_path("sarc_f.yaml")))
    definition["formula"] = {"expression": expression, "min": 0, "max": 10}
    return definition


def session_rows(definition: dict, first_seq: int) -> tuple[str, list[Row]]:
    q = load_questionnaire(bundled_path("sarc_f.yaml"))
    session_id = "s-" + uuid.uuid4().hex[:10]
    at = "2026-11-20T10:00:00Z"
    create = {
        "session_id": session_id,
        "patient_id": "NHC-0042",
        "questionnaire_id": q.id,
        "language": "en",
        "answered_by": "patient",
        "started_at": at,
        "definition": definition,
        "definition_sha256": digest(definition),
    }
    rows = [Row(first_seq, "create_session", session_id, create, 0.0, at)]
    for n, item in enumerate(q.items, 1):
        answer = {
            "item_id": item.id,
            "option": 1,
            "points": item.options[0].points,
            "attempt": 1,
            "channel": "touch",
            "answered_by": "patient",
            "t": float(n),
        }
        rows.append(Row(first_seq + n, "record_answer", session_id, answer, float(n), at))
    rows.append(Row(first_seq + len(rows), "finish_session", session_id, {"finished_at": at}, 99.0, at))
    return session_id, rows


def formula_workers(pid: int) -> list[int]:
    """The station's children running the formula worker."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text().rsplit(")", 1)[1].split()
                command = (entry / "cmdline").read_bytes()
            except OSError:
                continue
            if int(stat[1]) == pid and b"station.formula_worker" in command:
                found.append(int(entry.name))
    return found


@pytest.mark.parametrize("database", ["sqlite", "postgresql"])
def test_a_kiosk_formula_never_runs_in_the_station(database: str, request, station_factory) -> None:
    ward = make_ward(request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url"))
    station = station_factory(ward.db_url, args=("--formula-timeout", str(BUDGET_S)))
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    evil = definition_with(EVIL)
    evil_session, rows = session_rows(evil, 1)
    fine_session, more = session_rows(definition_with("3"), len(rows) + 1)
    for batch in (rows, more):
        response = kiosk.sync(batch)
        assert response.status_code == 200, response.text
    doctor = Staff(station.url)

    # unknown: shown, no total, nothing run, a doctor may approve it
    page = doctor.http.get(f"/sessions/{evil_session}").text
    assert 'id="unknown-definition"' in page and 'id="approve-definition"' in page
    assert "is not one this station knows" in page
    assert formula_workers(station.process.pid) == []

    # the harmless one first: a page read after the evil one's approval would run it there
    for definition, session_id in ((definition_with("3"), fine_session), (evil, evil_session)):
        approved = doctor.post(f"/definitions/{digest(definition)}/approve", back=f"/sessions/{session_id}")
        assert approved.status_code == 303
        if session_id == fine_session:  # a known formula runs in the formula process: its total
            fine = doctor.http.get(f"/sessions/{fine_session}").text
            assert 'id="total">3</b>' in fine and 'id="unknown-definition"' not in fine

    # the catastrophic one: /healthz answers all the while the page waits for the formula
    answered: list[httpx.Response] = []
    page_thread = threading.Thread(
        target=lambda: answered.append(doctor.http.get(f"/sessions/{evil_session}", timeout=PATIENCE_S))
    )
    page_thread.start()
    health = []
    while page_thread.is_alive():
        health.append(httpx.get(station.url + "/healthz", timeout=PATIENCE_S))
    page_thread.join()
    assert health and all(h.status_code == 200 for h in health)
    # the formula language (kiosk.core.questionnaire.formula) refuses a regular expression before
    # anything runs, so the page answers with why, however long the regex would have taken; the
    # formula process's time budget stays behind it for whatever the language lets through
    assert answered[0].status_code == 200
    assert "runs a regular expression" in answered[0].text
    # and it is not run again: its export answers at once, with no total
    exported = doctor.http.get(f"/sessions/{evil_session}/export.json")
    assert exported.status_code == 200
    assert not [e for e in exported.json()["entry"] if e["resource"]["resourceType"] == "Observation"]

    # SIGTERM still stops the station (and its formula process)
    workers = formula_workers(station.process.pid)
    station.process.terminate()
    assert station.process.wait(timeout=PATIENCE_S) is not None
    for pid in workers:
        assert not Path(f"/proc/{pid}").exists() or "Z" in Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1][:3]


def test_staff_register_a_definition_from_its_file(sqlite_url, capsys) -> None:
    from station import cli, db, known

    path = bundled_path("gds15.yaml")
    assert cli.main(["add-definition", "--db", sqlite_url, str(path)]) == 0
    sha = digest(canonical(load_questionnaire(path)))
    assert f"definition gds15 {sha} registered" in capsys.readouterr().out
    engine = db.make_engine(sqlite_url)
    with engine.connect() as connection:
        assert known.known(connection, [sha]) == {sha}
    engine.dispose()
    bad = Path(sqlite_url.removeprefix("sqlite:///")).with_name("bad.yaml")
    bad.write_text("id: nothing\n")
    assert cli.main(["add-definition", "--db", sqlite_url, str(bad)]) == 2
    assert "bad.yaml" in capsys.readouterr().err
