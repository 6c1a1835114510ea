"""A validation study at the station (issue 36, part 8), on SQLite and PostgreSQL: a clinician's
answers stored beside four patients' kiosk results, apart from them (the kiosk's answers, total,
review, count of results waiting and export are unchanged), audited and append-only; the study of
an instrument over its days takes each patient's latest result once, and its kappas, ICC and
limits are those of the pairs the test itself built; the CSV reads back to the same figures."""

from __future__ import annotations

import csv
import io
from datetime import date

import pytest
import sqlalchemy as sa

from bench._history import clone
from kiosk.core.questionnaire import load_questionnaire
from station import auth, db, exports, reference, results, study, sync
from station.agreement import icc_2_1, table_of, weighted_kappa
from station.sessions import NotFound, load
from tests.station._study_visits import FIRST_DAY, KIOSK, store_study_visits
from tests.station.conftest import make_ward
from tests.station.helpers import PATIENTS, record_patient

NURSE = auth.User("nurse.kim", "nurse")
DOCTOR = auth.User("dr.lopez", "doctor")
FIRST, LAST = date(2026, 11, 1), date(2026, 11, 20)


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request):
    url = request.getfixturevalue("sqlite_url" if request.param == "sqlite" else "pg_url")
    make_ward(url)
    engine = db.open_database(url)
    yield engine
    engine.dispose()


def _enter_all(engine, visits) -> None:
    q = load_questionnaire()
    for n, session_id in enumerate(visits.session_ids):
        by = NURSE if n % 2 else DOCTOR
        chosen = {item_id: str(option) for item_id, option in visits.clinician[n].items()}
        assert reference.record_answers(engine, q, session_id, chosen, by) == len(chosen)


def _total(options) -> int | None:
    score = load_questionnaire().score_answers(options)
    return score.total if score.complete else None


def test_the_clinicians_answers_stay_apart_from_the_kiosks_result(engine) -> None:
    visits = store_study_visits(engine)
    q = load_questionnaire()
    before_csv = exports.result_csv(engine, q, "study-0")
    waiting = results.waiting_count(engine)
    _enter_all(engine, visits)
    with engine.connect() as connection:
        _, stored = load(connection, "study-0")
        found = reference.answers_in(connection, ["study-0"])["study-0"]
        audit_rows = connection.execute(sa.select(sa.func.count()).select_from(db.audit)).scalar_one()
    assert {a.item_id: a.option for a in stored.answers} == visits.kiosk[0]  # the kiosk's, untouched
    assert found["transfers"].option == 3 and found["transfers"].entered_by == "dr.lopez"
    assert exports.result_csv(engine, q, "study-0") == before_csv  # no export carries them
    assert results.waiting_count(engine) == waiting and audit_rows == 0  # no review step either


def test_a_change_is_a_newer_row_and_the_table_refuses_updates(engine) -> None:
    visits = store_study_visits(engine)
    q = load_questionnaire()
    _enter_all(engine, visits)
    assert reference.record_answers(engine, q, "study-0", {"transfers": "3", "stairs": ""}, NURSE) == 0
    assert reference.record_answers(engine, q, "study-0", {"transfers": "4"}, NURSE) == 1
    with engine.connect() as connection:
        history = [e for e in reference.history_in(connection, "study-0") if e.item_id == "transfers"]
        latest = reference.answers_in(connection, ["study-0"])["study-0"]["transfers"]
    assert [(e.option, e.entered_by) for e in history] == [(3, "dr.lopez"), (4, "nurse.kim")]
    assert (latest.option, latest.entered_by) == (4, "nurse.kim")
    with pytest.raises(sa.exc.SQLAlchemyError, match="append-only"), engine.begin() as connection:
        connection.execute(db.reference_results.update().values(option=1))
    with pytest.raises(sa.exc.SQLAlchemyError, match="append-only"), engine.begin() as connection:
        connection.execute(db.reference_results.delete())


def test_entries_the_station_refuses(engine) -> None:
    store_study_visits(engine)
    q = load_questionnaire()
    with pytest.raises(reference.EntryRefused, match="^stairs: '7' is not one of its 3 answers"):
        reference.record_answers(engine, q, "study-0", {"feeding": "2", "stairs": "7"}, NURSE)
    with pytest.raises(reference.EntryRefused, match="'teleport' is not a question of barthel"):
        reference.record_answers(engine, q, "study-0", {"teleport": "1"}, NURSE)
    with pytest.raises(reference.EntryRefused, match="at least one question"):
        reference.record_answers(engine, q, "study-0", {"feeding": ""}, NURSE)
    with pytest.raises(NotFound):
        reference.record_answers(engine, q, "no-such-session", {"feeding": "2"}, NURSE)
    running = record_patient(PATIENTS / "barthel1.yaml", patient="NHC-0081009", first_seq=900)
    events = clone([r for r in running if r.kind != "finish_session"], "study-running", "NHC-0081009", FIRST_DAY, 900)
    with engine.begin() as connection:
        sync.intake(connection, KIOSK, sync.parse({"events": events}))
    with pytest.raises(reference.EntryRefused, match="the kiosk's result is running, not finished"):
        reference.record_answers(engine, q, "study-running", {"feeding": "2"}, NURSE)
    with engine.connect() as connection:  # nothing half-stored
        assert reference.answers_in(connection, ["study-0", "study-running"]) == {}


def test_the_study_of_the_barthel(engine) -> None:
    visits = store_study_visits(engine)
    _enter_all(engine, visits)
    assert study.instruments(engine) == [("barthel", "Barthel Index")]
    found = study.study(engine, load_questionnaire(), "barthel", FIRST, LAST)
    # the first patient's earlier result and the one after the last day are left out
    assert [p.session_id for p in found.pairs] == ["study-0", "study-1", "study-2", "study-3"]
    expected = [(_total(visits.kiosk[n]), _total(visits.clinician[n])) for n in range(4)]
    assert expected[3][0] is None and expected[3][1] is not None  # the kiosk missed two items
    assert [(p.kiosk_total, p.clinician_total) for p in found.pairs] == expected
    assert found.totals == 3
    complete = [pair for pair in expected if pair[0] is not None]
    assert found.icc.estimate == icc_2_1([[float(k), float(c)] for k, c in complete]).estimate
    assert found.limits.bias.value == pytest.approx(sum(k - c for k, c in complete) / 3)
    by_item = {i.item_id: i for i in found.items}
    stairs = [(visits.kiosk[n]["stairs"], visits.clinician[n]["stairs"]) for n in range(4)]
    assert by_item["stairs"].n == 4
    assert by_item["stairs"].kappa == weighted_kappa(table_of(stairs, 3))
    # the clinicians answered "minor help" to every patient's transfers: no kappa, and why
    assert by_item["transfers"].kappa is None and "same answer" in by_item["transfers"].problem
    assert by_item["grooming"].n == 3  # the fourth patient's kiosk never answered it
    assert by_item["feeding"].kappa.value == pytest.approx(1.0)  # the same answers on both sides


def test_a_study_with_too_few_patients_says_why(engine) -> None:
    visits = store_study_visits(engine)
    reference.record_answers(
        engine, load_questionnaire(), "study-0", {k: str(v) for k, v in visits.clinician[0].items()}, NURSE
    )
    found = study.study(engine, load_questionnaire(), "barthel", FIRST, LAST)
    assert found.totals == 1 and found.icc is None and found.limits is None
    assert "at least two subjects" in found.icc_problem and "at least three pairs" in found.limits_problem
    text = study.csv_text(found)
    rows = list(csv.reader(io.StringIO(text)))
    icc_row = next(r for r in rows if r and r[0] == "icc_2_1")
    assert icc_row[3:6] == ["", "", ""] and "at least two subjects" in icc_row[6]


def test_the_csv_reads_back_to_the_studys_figures(engine) -> None:
    visits = store_study_visits(engine)
    _enter_all(engine, visits)
    found = study.study(engine, load_questionnaire(), "barthel", FIRST, LAST)
    rows = list(csv.reader(io.StringIO(study.csv_text(found))))
    assert rows[0] == ["instrument", "barthel", "from", "2026-11-01", "to", "2026-11-20"]
    assert rows[1] == study.CSV_HEADER
    stats = {(r[0], r[1]): r for r in rows[2:] if r and r[0] != "session"}
    icc = stats[("icc_2_1", "total")]
    assert (int(icc[2]), float(icc[3]), float(icc[4]), float(icc[5])) == (
        3,
        round(found.icc.estimate.value, 4),
        round(found.icc.estimate.low, 4),
        round(found.icc.estimate.high, 4),
    )
    assert "McGraw & Wong" in icc[6]
    kappa = stats[("kappa", "stairs")]
    assert float(kappa[3]) == round(next(i for i in found.items if i.item_id == "stairs").kappa.value, 4)
    assert "quadratic" in kappa[6]
    assert stats[("kappa", "transfers")][3:6] == ["", "", ""] and "same answer" in stats[("kappa", "transfers")][6]
    assert float(stats[("bland_altman_lower", "total")][3]) == round(found.limits.lower.value, 4)
    patients = rows[rows.index(["session", "patient", "started_at", "kiosk_total", "clinician_total"]) + 1 :]
    assert [(r[0], r[3], r[4]) for r in patients] == [
        (p.session_id, "" if p.kiosk_total is None else str(p.kiosk_total), str(p.clinician_total)) for p in found.pairs
    ]


def test_the_period() -> None:
    today = date(2026, 11, 28)
    assert study.period("", "", today) == (date(2025, 11, 28), today)
    assert study.period("2026-11-01", "2026-11-20", today) == (FIRST, LAST)
    with pytest.raises(study.StudyError, match="^from: 'monday' is not a day"):
        study.period("monday", "2026-11-20", today)
    with pytest.raises(study.StudyError, match="is before from"):
        study.period("2026-11-20", "2026-11-01", today)
    with pytest.raises(study.StudyError, match="at most"):
        study.period("2020-01-01", "2026-11-20", today)
