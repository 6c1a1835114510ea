"""The visit code's throttle (issue 32, docs/visit-code.md): wrong codes space the kiosk's checks
and never refuse its right code. On a real station process (SQLite and PostgreSQL) under 100
concurrent guesses, and on the station's own functions over a simulated day of guessing."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import pytest
import sqlalchemy as sa

from kiosk.sync.http import Station
from kiosk.sync.orders import OrderRefused, start_order
from station import db, orders
from station.db import code_failures
from tests.station.conftest import make_ward
from tests.station.helpers import KioskClient, Staff
from tests.station.test_orders import code_of, order, state


def _move_failures_back(db_url: str, kiosk_id: str, seconds: float) -> None:
    """As if ``seconds`` had passed since every wrong code of the kiosk (the station reads the
    wall clock; the stored times are what it compares)."""
    engine = db.make_engine(db_url)
    try:
        with engine.begin() as connection:
            connection.execute(
                code_failures.update()
                .where(code_failures.c.kiosk_id == kiosk_id)
                .values(at=code_failures.c.at - seconds)
            )
    finally:
        engine.dispose()


@pytest.mark.slow
@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_a_hundred_concurrent_guesses_never_lock_the_right_code_out(database, request, station_factory):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)
    nurse = Staff(station.url, "nurse.kim", "nurse")
    placed = order(nurse, ward.kiosk_id)
    order_id, code = placed.headers["location"].rsplit("/", 1)[1], code_of(nurse, placed.headers["location"])
    guesses = [f"{n:04d}" for n in range(10_000) if f"{n:04d}" != code][:100]
    clients = [KioskClient(station.url, ward.token, ward.kiosk_id) for _ in range(10)]
    with ThreadPoolExecutor(max_workers=10) as pool:
        answers = list(pool.map(lambda n: clients[n % 10].start_order(guesses[n]), range(100)))
    statuses = sorted(a.status_code for a in answers)
    assert statuses == [404] * 2 + [429] * 98  # two checked at once, the others told when
    waits = {int(a.headers["retry-after"]) for a in answers if a.status_code == 429}
    assert waits and max(waits) <= orders.CODE_GAPS_S[2]

    for _ in range(20):  # a guesser keeps at it, taking each slot as it opens
        _move_failures_back(db_url, ward.kiosk_id, max(orders.CODE_GAPS_S))
        assert clients[0].start_order(guesses[-1]).status_code == 404
    assert clients[0].start_order(code).status_code == 429  # no code is looked at before its slot
    _move_failures_back(db_url, ward.kiosk_id, max(orders.CODE_GAPS_S))
    kiosk = Station(station.url, ward.token)  # the kiosk's own client, as its code pad sends it
    assert clients[0].start_order(guesses[-1]).status_code == 404
    with pytest.raises(OrderRefused, match=r"checks the next one in \d+ seconds: type it again then"):
        start_order(kiosk, code, instruments=["barthel"], languages=["en"])
    _move_failures_back(db_url, ward.kiosk_id, max(orders.CODE_GAPS_S))  # the longest wait there is
    started = start_order(kiosk, code, instruments=["barthel"], languages=["en"])
    assert started.id == order_id and state(db_url, order_id)[0] == "in_progress"
    for client in clients:
        client.close()


class _Clock:
    def __init__(self) -> None:
        self.t = 1_800_000_000.0

    def __call__(self) -> float:
        return self.t


def test_a_day_of_guessing_as_fast_as_allowed_gets_five_checks_per_ten_minutes(tmp_path, monkeypatch):
    """The brute-force figure the lockout had (5 per 10 minutes), kept by spacing alone."""
    engine = db.open_database(db.sqlite_url(tmp_path / "station"))
    clock = _Clock()
    monkeypatch.setattr(db, "now", clock)
    start = clock.t
    checked: list[float] = []
    while clock.t < start + 24 * 3600:
        with engine.begin() as connection:
            try:
                assert orders.start(connection, "ward3-bed2", "0000") is None
                checked.append(clock.t)
            except orders.TooManyCodes as slot:
                clock.t += slot.retry_after_s
    engine.dispose()
    first = [t for t in checked if t < start + orders.CODE_WINDOW_S]
    later = [t for t in checked if t >= start + orders.CODE_WINDOW_S]
    busiest = max(sum(1 for u in later if t <= u < t + orders.CODE_WINDOW_S) for t in later)
    assert (len(first), busiest) == (8, 5)
    assert len(checked) <= 8 + 5 * (24 * 6 - 1)  # 723 a day: 1.2% odds on a code open for 4 hours


def test_the_wait_grows_with_the_wrong_codes_and_is_never_longer_than_two_minutes(tmp_path, monkeypatch):
    engine = db.open_database(db.sqlite_url(tmp_path / "station"))
    clock = _Clock()
    monkeypatch.setattr(db, "now", clock)
    waits = []
    for _ in range(12):
        with engine.begin() as connection:
            waits.append(orders.next_check_in(connection, "ward3-bed2", clock.t))
            connection.execute(code_failures.insert().values(kiosk_id="ward3-bed2", at=clock.t))
    with engine.connect() as connection:
        other = orders.next_check_in(connection, "ward3-bed1", clock.t)
        stored = connection.execute(sa.select(sa.func.count()).select_from(code_failures)).scalar_one()
    engine.dispose()
    assert waits == [0, 0, 15, 60] + [120] * 8 and other == 0 and stored == 12
