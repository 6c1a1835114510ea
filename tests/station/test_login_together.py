"""Staff logging in at the same moment from one address (a ward PC, a NAT, the station's own
proxy) are let in: a colleague's try in flight counts toward the pauses, but a count that earns no
pause makes no one wait. Before, a try that waited for the address's lock saw the colleague's try
stamped after its own clock reading and was refused with 429 (seen in bench/station.py, whose
two nurses log in together)."""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor

import pytest

from station import auth, db, throttle
from station.db import login_failures
from tests.station.conftest import PASSWORDS, PATIENCE_S, make_ward
from tests.station.test_login_throttle import Browser

pytestmark = pytest.mark.slow


@pytest.fixture(params=["sqlite", "postgresql"])
def db_url(request, tmp_path):
    return db.sqlite_url(tmp_path / "data") if request.param == "sqlite" else request.getfixturevalue("pg_url")


def test_a_colleagues_try_in_flight_pauses_no_one(db_url):
    engine = db.open_database(db_url)
    try:
        # the colleague's try, counted until its password checks, stamped an instant after this
        # try read the clock (it held the address's lock meanwhile)
        with engine.begin() as connection:
            connection.execute(login_failures.insert().values(name="nurse.kim", address="10.1.2.3", at=db.now() + 1))
        assert throttle.admit(engine, "dr.lopez", "10.1.2.3") == (0.0, 1)
        # the pauses themselves stand: a name's fourth try in a row from one address waits
        for _ in range(throttle.FREE_FAILURES - 1):
            assert throttle.admit(engine, "dr.lopez", "10.1.2.3")[0] == 0.0
        wait, failures = throttle.admit(engine, "dr.lopez", "10.1.2.3")
        assert wait > 0 and failures == throttle.FREE_FAILURES
    finally:
        engine.dispose()


def test_staff_logging_in_together_from_one_address_all_get_in(db_url, station_factory):
    make_ward(db_url)
    engine = db.make_engine(db_url)
    names = [f"nurse.{i}" for i in range(8)]
    for name in names:
        auth.add_user(engine, name, "nurse", PASSWORDS["nurse"])
    engine.dispose()
    station = station_factory(db_url)
    browsers = [Browser(station.url) for _ in names]
    ready = threading.Barrier(len(browsers))

    def login(pair: tuple[Browser, str]) -> int:
        ready.wait(PATIENCE_S)
        return pair[0].login(pair[1], PASSWORDS["nurse"]).status_code

    with ThreadPoolExecutor(len(browsers)) as pool:
        statuses = list(pool.map(login, zip(browsers, names)))
    assert statuses == [303] * len(names)
    assert 'id="kiosks"' in browsers[0].http.get("/").text
