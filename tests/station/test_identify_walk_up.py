"""A walk-up result given the patient's hospital identifier at the station (issue 36), against a
real `kiosk station` process with a site identifier rule, on SQLite and PostgreSQL: the rule and
names are refused with one message, the change is in the audit trail (who, when, old, new, why),
the page, the patient's course and both exports carry the new identifier, the kiosk's later rows
never put the old one back, an ordered visit is never re-identified, and a signed result is final."""

from __future__ import annotations

import re
from urllib.parse import unquote

import pytest

from tests.station.conftest import make_ward
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient
from tests.station.test_orders import code_of, order

pytestmark = pytest.mark.slow
RULE = "NHC-[0-9]{7}"
NEW = "NHC-0036201"


def _message(response) -> str:
    """The message a redirect carries back to the page."""
    assert response.status_code == 303, response.text
    return unquote(re.search(r"message=([^&]*)", response.headers["location"]).group(1))


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_staff_give_a_walk_up_result_its_identifier_before_sign_off(database, request, station_factory):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url, args=("--patient-id-pattern", RULE))
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    nurse, doctor = Staff(station.url, "nurse.kim", "nurse"), Staff(station.url)

    rows = record_patient(PATIENTS / "barthel1.yaml", visit="walk-up")
    session_id, old = rows[0].session_id, rows[0].payload["patient_id"]
    finish = next(i for i, r in enumerate(rows) if r.kind == "finish_session")
    assert kiosk.sync(rows[:finish]).status_code == 200  # the visit running: the end comes later
    page = f"/sessions/{session_id}"
    assert 'id="identify-form"' in nurse.http.get(page).text

    for refused, why in (("Maria Lopez", "never a name"), ("NHC-12", f"the site's identifiers match {RULE}")):
        assert why in _message(nurse.post(f"{page}/identify", patient_id=refused))
    assert _message(nurse.post(f"{page}/identify", patient_id=NEW, reason="wristband checked")) == (
        f"The result is now filed under {NEW} (it was recorded as {old})."
    )
    assert kiosk.sync(rows[finish:]).status_code == 200  # the kiosk's later rows keep staff's identifier

    shown = nurse.http.get(page).text
    assert f"Patient {NEW}" in shown and f"patient identifier {old} -&gt; {NEW}: wristband checked" in shown
    assert "nurse.kim" in shown.split("Audit trail", 1)[1]
    assert session_id in nurse.http.get(f"/patients/{NEW}").text
    bundle = nurse.http.get(f"{page}/export.json").text
    csv = nurse.http.get(f"{page}/export.csv").text
    for export in (bundle, csv):
        assert NEW in export and old not in export

    # a doctor signs it off: from then on it is final, identifier included
    assert doctor.post(f"{page}/sign-off").status_code == 303
    assert "signed off" in _message(nurse.post(f"{page}/identify", patient_id="NHC-0036202"))
    assert 'id="identify-closed"' in nurse.http.get(page).text
    assert NEW in nurse.http.get(f"{page}/export.json").text

    # an ordered visit names its patient from the order: never re-identified here
    placed = order(nurse, ward.kiosk_id, patient="NHC-0036203")
    order_id = placed.headers["location"].rsplit("/", 1)[1]
    assert kiosk.start_order(code_of(nurse, placed.headers["location"])).status_code == 200
    ordered = record_patient(
        PATIENTS / "barthel1.yaml", first_seq=len(rows) + 1, patient="NHC-0036203", visit=f"order {order_id}"
    )
    assert kiosk.sync(ordered).status_code == 200
    ordered_page = f"/sessions/{ordered[0].session_id}"
    assert "only a walk-up result" in _message(nurse.post(f"{ordered_page}/identify", patient_id="NHC-0036204"))
    assert 'id="identify-form"' not in nurse.http.get(ordered_page).text
    kiosk.close()
