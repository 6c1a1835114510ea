"""History never slows today's work (issue 37, part 2), on SQLite and PostgreSQL: where a result's
review stands is stored with the sign-off (the count of results waiting follows intake, sign-off
and reopening, and a migration fills it in for results signed before), the inbox pages by keyset
without losing or repeating a result, patients are found by identifier prefix, and the month's
export streams the same entries the whole Bundle held. The results are loaded through the
station's own intake and sign-off (bench/_history.py)."""

from __future__ import annotations

import json
from datetime import UTC, date, datetime

import pytest
import sqlalchemy as sa
from alembic import command
from alembic.config import Config

from bench._history import load_history
from kiosk.core.questionnaire import load_questionnaire
from kiosk.export import bundle_of
from station import auth, db, exports, results, validation, visit_inbox
from tests.station.conftest import make_ward
from tests.station.helpers import PATIENTS, Staff, record_patient

NOW = datetime(2026, 11, 20, 12, 0, tzinfo=UTC)


@pytest.fixture(scope="module")
def template():
    return record_patient(PATIENTS / "barthel5.yaml")


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request):
    url = request.getfixturevalue("sqlite_url" if request.param == "sqlite" else "pg_url")
    make_ward(url)
    engine = db.open_database(url)
    yield engine
    engine.dispose()


def _load(engine, template, count: int = 12, signed: float = 0.5) -> None:
    load_history(
        engine, template, results=count, patients=5, years=0.25, kiosks=["ward3-bed2"], signed_fraction=signed, now=NOW
    )


def test_waiting_count_is_stored_with_each_change(engine, template) -> None:
    _load(engine, template)
    assert results.waiting_count(engine) == 6
    doctor = auth.User("dr.lopez", "doctor")
    validation.sign_off(engine, "history-0000011", doctor, incomplete="a generated result with a gap")
    assert results.waiting_count(engine) == 5
    validation.amend(engine, "history-0000000", "new information", doctor)
    assert results.waiting_count(engine) == 6
    # the stored state agrees with the audit trail's reading of every result
    with engine.connect() as connection:
        stored = dict(connection.execute(sa.select(db.sessions.c.id, db.sessions.c.signed_at)).all())
    reviews = validation.reviews(engine, list(stored))
    assert {s: r.signed_at if r.final else None for s, r in reviews.items()} == stored


def test_migration_fills_in_where_signed_results_stand(engine, template) -> None:
    _load(engine, template, count=6)
    validation.amend(engine, "history-0000001", "rechecked", auth.User("dr.lopez", "doctor"))
    with engine.connect() as connection:
        before = dict(connection.execute(sa.select(db.sessions.c.id, db.sessions.c.signed_at)).all())
    assert sum(v is not None for v in before.values()) == 2
    config = Config()
    config.set_main_option("script_location", str(db.MIGRATIONS))
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.downgrade(config, "0005_orders")
    db.migrate(engine)
    with engine.connect() as connection:
        assert dict(connection.execute(sa.select(db.sessions.c.id, db.sessions.c.signed_at)).all()) == before


def test_inbox_keyset_pages_lose_and_repeat_nothing(engine, template) -> None:
    _load(engine, template, count=11, signed=0.0)
    q = load_questionnaire()
    seen, after, pages = [], "", 0
    while True:
        page = visit_inbox.inbox(engine, q, state="all", after=after, limit=4)
        seen += [r.session_id for r in page.results]
        pages += 1
        if not page.after:
            break
        after = page.after
    assert pages == 3
    assert seen == [f"history-{n:07d}" for n in reversed(range(11))]  # newest first, each once


def test_search_by_identifier_prefix(engine, template) -> None:
    _load(engine, template, count=6)
    found = results.search(engine, "nhc-0000000")  # typed in lower case: found in capitals
    assert [(p, n) for p, n, _ in found] == [("NHC-0000000", 2)]
    assert {p for p, _, _ in results.search(engine, "NHC-")} == {f"NHC-{n:07d}" for n in range(5)}
    assert results.search(engine, "0000001") == []  # a prefix, not any part of the identifier
    assert results.search(engine, "NHC-%") == []  # LIKE's wildcards are plain characters


def test_month_export_streams_the_whole_bundle(engine, template) -> None:
    _load(engine, template, count=12, signed=1.0)
    q = load_questionnaire()
    first, last = date(2026, 10, 1), date(2026, 11, 30)
    chosen = exports.signed_off_in(engine, first, last)
    assert chosen and len(chosen) < 12
    streamed = exports.period_bundle(engine, q, first, last)
    with engine.connect() as connection:
        whole = bundle_of([exports._described(connection, q, s) for s in chosen])
    key = lambda e: e["fullUrl"]  # noqa: E731
    assert sorted(streamed["entry"], key=key) == sorted(whole["entry"], key=key)
    # nothing signed in a month with no sign-off: a Bundle without entries
    assert exports.period_bundle(engine, q, date(2001, 1, 1), date(2001, 1, 31)) == {
        "resourceType": "Bundle",
        "type": "transaction",
    }
    assert json.dumps(streamed)  # plain JSON all through


def test_results_waiting_on_every_page(sqlite_url, station_factory, template) -> None:
    """The navigation's count is the same on the ward, the inbox and a result's own page."""
    make_ward(sqlite_url)
    engine = db.make_engine(sqlite_url)
    _load(engine, template, count=5, signed=0.4)
    engine.dispose()
    station = station_factory(sqlite_url)
    staff = Staff(station.url)
    for path in ("/", "/inbox", "/sessions/history-0000004", "/sessions/history-0000000", "/patients?q=NHC"):
        page = staff.http.get(path)
        assert page.status_code == 200, path
        assert 'id="waiting-count">3<' in page.text, path
