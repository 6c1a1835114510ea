"""The station's Timed Up and Go results read back, on SQLite and PostgreSQL (issue 34, part 5):
a session's page and print view hold the TUG of their visit (its order), a patient's course every
TUG (one of no questionnaire's visit as a visit of its own), and the exports give the kiosk's own
Observation (LOINC 89423-8 in s, camera or stopwatch as the method), checked by the independent
FHIR checkers, and its CSV."""

from __future__ import annotations

import csv
import io
from datetime import date
from zoneinfo import ZoneInfo

import pytest

from kiosk.core.questionnaire import load_questionnaire
from station import db, exports, printing, tug_exports, tugs
from tests.kiosk.export.standard import check_fhir
from tests.station._tug import store_tug_visits
from tests.station.conftest import make_ward
from tests.station.test_orders import state

UTC = ZoneInfo("UTC")


@pytest.fixture(params=["sqlite", "postgresql"])
def stored(request, tmp_path):
    url = request.getfixturevalue("sqlite_url" if request.param == "sqlite" else "pg_url")
    make_ward(url)
    engine = db.open_database(url)
    yield engine, url, store_tug_visits(engine, tmp_path)
    engine.dispose()


def tug_observations(bundle: dict) -> list[dict]:
    return [
        e["resource"]
        for e in bundle.get("entry", [])
        if e["resource"]["resourceType"] == "Observation" and e["resource"]["code"]["coding"][0]["code"] == "89423-8"
    ]


def test_a_visits_tug_is_on_its_session_and_in_its_order(stored) -> None:
    engine, url, visits = stored
    (shown,) = tugs.of_session(engine, visits.barthel)
    assert shown.id == visits.camera and shown.order_id == visits.order_id
    assert shown.wording.endswith("not above the site's threshold (13.5 s).")
    assert shown.decision_words == "dr-lee accepted the camera's time"
    assert [name for name, _ in shown.phase_rows] == ["Sit to stand", "Walk out", "Turn", "Walk back", "Turn and sit"]
    assert [t.id for t in tugs.of_order(engine, visits.order_id)] == [visits.camera]
    assert state(url, visits.order_id)[0] == "awaiting_validation"  # the Barthel and the TUG are done


def test_the_print_view_and_the_course_hold_the_tugs(stored) -> None:
    engine, _, visits = stored
    q = load_questionnaire()
    printed = printing.visit(engine, q, visits.barthel, zone=UTC)
    assert [r.session_id for r in printed.results] == [visits.barthel]
    assert [p.tug.id for p in printed.tugs] == [visits.camera]
    course = printing.course(engine, q, visits.patient_id, zone=UTC)
    assert [([r.session_id for r in v.results], [p.tug.id for p in v.tugs]) for v in course] == [
        ([], [visits.stopwatch]),  # a staff visit of a TUG alone, 2026-11-02
        ([visits.barthel], [visits.camera]),
    ]
    assert course[0].date == "2026-11-02 08:00 UTC"
    alone = printing.tug_visit(engine, q, visits.stopwatch, zone=UTC)
    assert alone is not None and [p.tug.id for p in alone.tugs] == [visits.stopwatch] and not alone.results
    assert printing.tug_visit(engine, q, "no-such-tug") is None


def test_the_exports_give_the_kiosks_observation(stored) -> None:
    engine, _, visits = stored
    (camera,) = tug_observations(exports.result_bundle(engine, load_questionnaire(), visits.barthel))
    check_fhir(camera)
    assert camera["valueQuantity"]["unit"] == "s" and camera["valueQuantity"]["code"] == "s"
    assert camera["method"]["coding"][0]["code"] == "camera" and "device" in camera
    assert camera["performer"][0]["identifier"]["value"] == "dr-lee"
    assert len(camera["component"]) == 5 + 2  # the phases, the Get Up & Go rating, the walking aid
    assert "hosp-north/ward3-bed2/" in camera["identifier"][0]["value"]  # the kiosk's own identity

    period = exports.period_bundle(engine, load_questionnaire(), date(2026, 11, 1), date(2026, 11, 30))
    found = {o["method"]["coding"][0]["code"]: o for o in tug_observations(period)}
    assert set(found) == {"camera", "stopwatch"}  # the Barthel is not signed off: only the TUGs
    check_fhir(period)
    assert found["stopwatch"]["valueQuantity"]["value"] == 15.5 and "device" not in found["stopwatch"]
    assert found["stopwatch"]["note"][0]["text"] == "above the site's threshold (13.5 s)"
    assert (
        tug_observations(exports.period_bundle(engine, load_questionnaire(), date(2026, 10, 1), date(2026, 10, 31)))
        == []
    )

    rows = list(csv.DictReader(io.StringIO(tug_exports.csv_text(tugs.patient_course(engine, visits.patient_id)))))
    assert [(r["result_id"], r["method"], r["measure"]) for r in rows][:2] == [
        (visits.stopwatch, "stopwatch", "total"),
        (visits.camera, "camera", "total"),
    ]
    assert len(rows) == 2 + 5 and rows[0]["seconds"] == "15.50" and rows[0]["accepted_by"] == "nurse-7"


def test_a_patient_with_only_tugs_is_found_and_a_tug_never_takes_a_sessions_id(stored, tmp_path) -> None:
    from dataclasses import replace

    from station import results, sync
    from tests.station._tug import stopwatch_result, tug_rows

    engine, _, visits = stored
    (row,) = tug_rows(tmp_path / "k", [("NHC-0034999", stopwatch_result(), "2026-11-25T09:00:00Z")])
    with engine.begin() as connection:
        sync.intake(connection, "ward3-bed2", sync.parse({"events": [replace(row, seq=900).event()]}))
    assert results.search(engine, "nhc-003499") == [("NHC-0034999", 1, "2026-11-25T09:00:00Z")]
    found = dict((p, n) for p, n, _ in results.search(engine, "NHC-00341"))
    assert found == {visits.patient_id: 3}  # the Barthel and two TUGs
    clash = replace(row, seq=901, session_id=visits.barthel)
    clash.payload["tug_id"] = visits.barthel
    with pytest.raises(sync.Conflict, match=r"seq 901: record_tug.tug_id: .* is a session's id"):
        with engine.begin() as connection:
            sync.intake(connection, "ward3-bed2", sync.parse({"events": [clash.event()]}))


def test_an_order_of_the_tug_alone_is_refused_by_the_use_case(stored) -> None:
    """The kiosk gives the TUG within a visit (beside a questionnaire): the order use case refuses
    the TUG alone, whatever form or client asks, and stores nothing."""
    import sqlalchemy as sa

    from station import auth, orders

    engine, _, _ = stored
    with engine.connect() as connection:
        before = connection.execute(sa.select(sa.func.count()).select_from(db.orders)).scalar_one()
    with pytest.raises(orders.OrderError, match="the Timed Up and Go is given within a visit"):
        orders.create(
            engine,
            kiosk_id="ward3-bed2",
            patient_id="NHC-0034600",
            instruments=["tug"],
            language="en",
            relative=False,
            by=auth.User("nurse.kim", "nurse"),
            known_instruments=["barthel", "tug"],
            languages=["en"],
        )
    with engine.connect() as connection:
        assert connection.execute(sa.select(sa.func.count()).select_from(db.orders)).scalar_one() == before
