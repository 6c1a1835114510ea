"""The visit as the unit at the ward (issue 36, part 1), on SQLite and PostgreSQL: a battery of
three instruments is one visit (found by its order or any of its sessions), read with each
instrument's total, band, state, staff items and changes in words; it is signed off in ONE
sign-off (every result or none: a result with unanswered items only as incomplete, with a
reason; a visit changed since it was read is refused); the inbox lists visits, keyset paged
without losing or repeating one whose instruments straddle a page's end; a patient's search
counts visits. The sessions come from real kiosk stores through the station's intake."""

from __future__ import annotations

import pytest
import sqlalchemy as sa

from kiosk.core.questionnaire import load_questionnaire
from station import db, results, staff_items, sync, validation, visit_inbox, visit_review
from station.sessions import NotFound
from tests.station._battery import DOCTOR, NURSE, store_battery
from tests.station._visits import PATIENT
from tests.station.conftest import make_ward
from tests.station.test_staff_items import _rows

REASON = "patient too tired to be weighed; not to be repeated"


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request):
    url = request.getfixturevalue("sqlite_url" if request.param == "sqlite" else "pg_url")
    make_ward(url)
    engine = db.open_database(url)
    yield engine
    engine.dispose()


def _order_state(engine, order_id: str) -> str:
    with engine.connect() as connection:
        return connection.execute(sa.select(db.orders.c.state).where(db.orders.c.id == order_id)).scalar_one()


def test_a_battery_is_one_visit_read_in_words(engine, tmp_path) -> None:
    battery = store_battery(engine, tmp_path)
    q = load_questionnaire()
    visit = visit_review.read(engine, q, battery.order_id)
    assert [visit_review.read(engine, q, s).key for s in (battery.barthel, battery.walking)] == [battery.order_id] * 2
    assert (visit.patient_id, visit.order_id) == (PATIENT, battery.order_id)
    barthel, mood, walking = visit.results  # in the order's order
    assert [r.printed.title for r in visit.results] == ["Barthel Index", "Mood check (4 items)", "Walking"]
    assert (barthel.printed.total_words, barthel.printed.band, barthel.state) == (
        "100 of 100",
        "Independent",
        "unreviewed",
    )
    assert (mood.printed.total_words, mood.printed.band, mood.printed.answered_by) == (
        "20 of 25",
        "Suggests depression",
        "the patient",
    )
    assert walking.staff == ["Weight: not entered", "Uses a walking aid: not entered"]
    assert walking.missing == ["Weight", "Uses a walking aid"] and walking.will_be_words == "signed off as incomplete"
    assert all(r.signable and not r.changes for r in visit.results)
    # staff enter the weight and correct a mood answer: both are said in words, with labels
    staff_items.enter_value(engine, battery.q, battery.walking, "weight", "72,125", NURSE)
    mood_q = visit_review.questionnaire_of(engine, battery.mood)
    validation.change_item(engine, mood_q, battery.mood, "satisfied", 1, "misheard: she said yes", NURSE)
    _, mood, walking = visit_review.read(engine, q, battery.order_id).results
    assert mood.changes == [
        "Are you basically satisfied with your life?: “No” changed to “Yes” by nurse.kim (“misheard: she said yes”)"
    ]
    assert (mood.state, mood.will_be, mood.printed.total_words) == ("corrected", "amended", "15 of 25")
    assert walking.changes == ["Weight: 72.125 kg entered by nurse.kim"]
    assert walking.staff[0] == "Weight: 72.125 kg (entered by nurse.kim)" and walking.missing == ["Uses a walking aid"]
    with pytest.raises(NotFound):
        visit_review.read(engine, q, "no-such-visit")


def test_a_battery_of_three_is_signed_off_in_one_sign_off(engine, tmp_path) -> None:
    battery = store_battery(engine, tmp_path)
    q = load_questionnaire()
    staff_items.enter_value(engine, battery.q, battery.walking, "weight", "64", NURSE)
    validation.change_item(engine, battery.q, battery.walking, "aid", 2, "uses a stick", NURSE)
    visit = visit_review.read(engine, q, battery.mood)
    assert len(visit.signable) == 3 and not visit.results[2].missing
    with pytest.raises(validation.ValidationError, match="only a doctor"):
        visit_review.sign_off(engine, q, battery.order_id, NURSE, seen=visit.seen)
    signed = visit_review.sign_off(engine, q, battery.order_id, DOCTOR, seen=visit.seen)
    assert signed == [battery.barthel, battery.mood, battery.walking]
    reviews = validation.reviews(engine, signed)
    assert all(r.final and r.signed_by == "dr.lopez" for r in reviews.values())
    assert len({r.signed_at for r in reviews.values()}) == 1  # one sign-off, one moment
    assert _order_state(engine, battery.order_id) == "signed_off"
    assert results.waiting_count(engine) == 1  # the walk-up alone waits
    after = visit_review.read(engine, q, battery.order_id)
    assert [r.state for r in after.results] == ["signed_off", "signed_off", "amended"] and not after.signable
    with pytest.raises(validation.ValidationError, match="changed since you read it"):
        visit_review.sign_off(engine, q, battery.order_id, DOCTOR, seen=visit.seen)
    with pytest.raises(validation.ValidationError, match="nothing in this visit waits"):
        visit_review.sign_off(engine, q, battery.order_id, DOCTOR, seen=after.seen)
    # amend after sign-off stays per result: the order waits again, the visit offers one sign-off
    validation.amend(engine, battery.mood, "the daughter says she is often bored", DOCTOR)
    reopened = visit_review.read(engine, q, battery.order_id)
    assert [r.session_id for r in reopened.signable] == [battery.mood]
    assert _order_state(engine, battery.order_id) == "awaiting_validation"
    assert visit_review.sign_off(engine, q, battery.order_id, DOCTOR, seen=reopened.seen) == [battery.mood]
    assert _order_state(engine, battery.order_id) == "signed_off"


def test_an_incomplete_result_is_refused_without_a_reason_and_nothing_is_signed(engine, tmp_path) -> None:
    battery = store_battery(engine, tmp_path)
    q = load_questionnaire()
    visit = visit_review.read(engine, q, battery.order_id)
    for reasons in ({}, {battery.walking: "   "}):
        with pytest.raises(
            validation.ValidationError,
            match=r"Walking: 2 items not answered \(weight, aid\): sign off as incomplete.*nothing was signed off",
        ):
            visit_review.sign_off(engine, q, battery.order_id, DOCTOR, seen=visit.seen, reasons=reasons)
        assert not any(r.final for r in validation.reviews(engine, [battery.barthel, battery.mood]).values())
    assert _order_state(engine, battery.order_id) == "awaiting_validation"
    signed = visit_review.sign_off(
        engine, q, battery.order_id, DOCTOR, seen=visit.seen, reasons={battery.walking: REASON}
    )
    assert len(signed) == 3
    assert validation.review(engine, battery.walking).incomplete == REASON
    assert validation.review(engine, battery.barthel).incomplete == ""


def test_the_inbox_lists_each_visit_once_across_its_pages(engine, tmp_path) -> None:
    battery = store_battery(engine, tmp_path)
    q = load_questionnaire()
    page = visit_inbox.inbox(engine, q)
    assert [v.key for v in page.visits] == [battery.order_id, battery.walk_up] and page.after == ""
    assert [r.session_id for r in page.visits[0].results] == [battery.barthel, battery.mood, battery.walking]
    assert page.visits[0].waiting == 3
    # one visit a page: the battery's three results never spill onto the next page
    seen, after = [], ""
    while True:
        page = visit_inbox.inbox(engine, q, state="all", after=after, limit=1)
        seen += [v.key for v in page.visits]
        if not page.after:
            break
        after = page.after
    assert seen == [battery.order_id, battery.walk_up]
    # the battery's newest result signed: the visit still waits (two results), anchored on the next
    validation.sign_off(engine, battery.walking, DOCTOR, incomplete=REASON)
    waiting = visit_inbox.inbox(engine, q, limit=1)
    assert [v.key for v in waiting.visits] == [battery.order_id] and waiting.visits[0].waiting == 2
    assert [v.key for v in visit_inbox.inbox(engine, q, after=waiting.after).visits] == [battery.walk_up]
    assert [v.key for v in visit_inbox.inbox(engine, q, state="signed").visits] == [battery.order_id]
    assert visit_inbox.inbox(engine, q, kiosk_id="another-kiosk").visits == []


def test_a_patients_visits_and_search_count_visits(engine, tmp_path) -> None:
    battery = store_battery(engine, tmp_path)
    assert [(p, n) for p, n, _ in results.search(engine, PATIENT)] == [(PATIENT, 2)]  # not 4 results
    course = results.course(engine, load_questionnaire(), PATIENT)
    visits = visit_inbox.patient_visits(course)
    assert [v.key for v in visits] == [battery.order_id, battery.walk_up]  # newest first
    assert [(r.instrument, r.total_words, r.band_label) for r in visits[0].results] == [
        ("Barthel Index", "100 of 100", "Independent"),
        ("Mood check (4 items)", "20 of 25", "Suggests depression"),
        ("Walking", "incomplete", ""),
    ]


def test_a_number_staff_entered_at_the_kiosk_counts_on_the_visit_and_in_the_lists(engine, tmp_path) -> None:
    """The weight staff typed at the kiosk is a line of the session's log: the visit, the inbox and
    the patient's course score with it (they read the log's events, not only the answers)."""
    rows = _rows(tmp_path, kiosk_weight=64.0)
    with engine.begin() as connection:
        sync.intake(connection, "ward3-bed2", sync.parse({"events": [r.event() for r in rows]}))
    session_id, q = rows[0].session_id, load_questionnaire()
    validation.change_item(engine, load_questionnaire(tmp_path / "walking.yaml"), session_id, "aid", 2, "stick", NURSE)
    (walking,) = visit_review.read(engine, q, session_id).results
    assert walking.staff == ["Weight: 64 kg (entered by kiosk staff at the kiosk)", "Uses a walking aid: “An aid”"]
    assert (walking.printed.total_words, walking.missing) == ("6 of 9", [])
    (listed,) = visit_inbox.inbox(engine, q).visits
    assert [r.total_words for r in listed.results] == ["6 of 9"]
