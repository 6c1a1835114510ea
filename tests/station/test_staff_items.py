"""Staff items at the station: a session of an instrument with a staff-measured weight and a staff
choice arrives from a real kiosk store (its outbox, over HTTP); the page says it waits for staff;
a nurse enters the weight (a number in range; out of range is one sentence, nothing stored) and
fills the choice, and the total appears. A weight staff entered at the kiosk arrives with the rest."""

from __future__ import annotations

import json
import re
import sqlite3
from pathlib import Path

import pytest

from bench._station_client import Row
from kiosk.commands.replay import load_script, run_script
from kiosk.core.questionnaire import load_questionnaire
from kiosk.store.database import DB_NAME, Store
from tests.kiosk.ui.test_six_options import SIX
from tests.station.conftest import make_ward, new_kiosk, shared_station  # noqa: F401 - the station fixture
from tests.station.helpers import KioskClient, Staff

pytestmark = pytest.mark.slow

SCRIPT = """\
patient: P-STAFF1
familiarisation: false
questions:
  - {item: steps, attempt: 1, channel: touch, option: 3, after: 2}
  - {item: stairs, attempt: 1, channel: remote, option: 4, after: 2}
"""


def _rows(tmp_path: Path, *, kiosk_weight: float | None) -> list[Row]:
    """The outbox of a real kiosk store after the scripted visit (and staff's weight, if given)."""
    (tmp_path / "walking.yaml").write_text(SIX, encoding="utf-8")
    (tmp_path / "patient.yaml").write_text(SCRIPT, encoding="utf-8")
    q = load_questionnaire(tmp_path / "walking.yaml")
    data = tmp_path / "kiosk"
    with Store.open(data, outbox=True) as store:
        result = run_script(load_script(tmp_path / "patient.yaml", q), q, store=store)
        if kiosk_weight is not None:
            store.record_staff_answer(
                result.session.id, item_id="weight", option=None, points=None, value=kiosk_weight, by="kiosk staff"
            )
    with sqlite3.connect(data / DB_NAME) as connection:
        stored = connection.execute("SELECT kind, session_id, payload, at FROM outbox ORDER BY seq").fetchall()
    return [Row(seq, kind, sid, json.loads(body), 0.0, at) for seq, (kind, sid, body, at) in enumerate(stored, 1)]


def _sync(station, ward, rows: list[Row]) -> str:
    name, token = new_kiosk(ward.db_url)
    client = KioskClient(station.url, token, name)
    try:
        answer = client.sync(rows)
    finally:
        client.close()
    assert answer.status_code == 200, answer.text
    assert not answer.json().get("parked"), answer.text
    return rows[0].session_id


def _total(html: str) -> str:
    found = re.search(r'<p class="total">(.*?)</p>', html, re.S)
    assert found, html[:3000]
    return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", "", found.group(1))).strip()


def test_a_nurse_enters_the_weight_and_the_aid_and_the_total_appears(shared_station, tmp_path):
    _a_nurse_completes_the_staff_items(*shared_station, tmp_path)


def test_the_same_on_postgresql(pg_url, station_factory, tmp_path):
    ward = make_ward(pg_url)
    _a_nurse_completes_the_staff_items(station_factory(ward.db_url), ward, tmp_path)


def _a_nurse_completes_the_staff_items(station, ward, tmp_path: Path) -> None:
    session_id = _sync(station, ward, _rows(tmp_path, kiosk_weight=None))
    staff = Staff(station.url, name="nurse.kim", role="nurse")
    page = staff.http.get(f"/sessions/{session_id}")
    assert page.status_code == 200, page.text[:2000]
    assert _total(page.text).startswith("No total yet: waiting for staff: Weight (kg), Uses a walking aid")
    refused = staff.post(f"/sessions/{session_id}/staff/weight", value="300")
    assert refused.status_code == 303
    back = staff.http.get(refused.headers["location"])
    assert "weight: &#39;300&#39; is not a number from 20 to 250 kg" in back.text, back.text[:3000]
    assert _total(back.text).startswith("No total yet: waiting for staff: Weight (kg), Uses a walking aid")
    entered = staff.post(f"/sessions/{session_id}/staff/weight", value="71,5")
    assert entered.status_code == 303
    filled = staff.post(f"/sessions/{session_id}/items/aid", option="1", reason="no aid seen on the ward")
    assert filled.status_code == 303
    page = staff.http.get(f"/sessions/{session_id}")
    # steps option 3 = 2 points, stairs option 4 = 3 points, aid option 1 = 0 points
    assert _total(page.text).startswith("Total 5 of 9"), _total(page.text)
    assert "71.5 kg" in page.text and "entered by staff" in page.text
    assert "P-STAFF1" in page.text


def test_a_weight_entered_at_the_kiosk_reaches_the_station(shared_station, tmp_path):
    station, ward = shared_station
    session_id = _sync(station, ward, _rows(tmp_path, kiosk_weight=64.0))
    staff = Staff(station.url, name="nurse.kim", role="nurse")
    page = staff.http.get(f"/sessions/{session_id}")
    assert _total(page.text).startswith("No total yet: waiting for staff: Uses a walking aid"), _total(page.text)
    assert "64 kg" in page.text
