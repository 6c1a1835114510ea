"""Staff logins end on the server: after logout a saved copy of the login cookie no longer opens
the ward page, and a password change (`kiosk station passwd`) or the user's removal
(`kiosk station remove-user`) ends every login of that user at once. Real station processes on
SQLite and PostgreSQL, the real command line, HTTP as a browser would send it."""

from __future__ import annotations

import httpx
import pytest
import sqlalchemy as sa

from station import auth, db, logins
from tests.station.conftest import PASSWORDS, make_ward
from tests.station.helpers import Staff
from tests.station.test_cli import kiosk_station

pytestmark = pytest.mark.slow


@pytest.fixture(params=["sqlite", "postgresql"])
def db_url(request, tmp_path):
    return db.sqlite_url(tmp_path / "data") if request.param == "sqlite" else request.getfixturevalue("pg_url")


def opens_ward(url: str, cookies: httpx.Cookies) -> bool:
    """Whether a client holding exactly these cookies sees the ward page (not the login)."""
    with httpx.Client(base_url=url, cookies=cookies, timeout=30) as client:
        page = client.get("/")
        events = client.get("/events", headers={"accept": "text/event-stream"}) if page.status_code != 200 else None
    if page.status_code == 200:
        assert 'id="kiosks"' in page.text
        return True
    assert page.status_code == 303 and page.headers["location"].startswith("/login")
    assert events is not None and events.status_code == 401
    return False


def saved(staff: Staff) -> httpx.Cookies:
    return httpx.Cookies({c.name: c.value for c in staff.http.cookies.jar})


def test_logout_password_change_and_removal_end_logins(db_url, station_factory, tmp_path):
    ward = make_ward(db_url)
    station = station_factory(db_url)

    doctor = Staff(station.url, "dr.lopez", "doctor")
    copy = saved(doctor)
    assert opens_ward(station.url, copy)
    assert doctor.post("/logout").status_code == 303
    assert not opens_ward(station.url, copy)
    assert not opens_ward(station.url, doctor.http.cookies)

    phone, desk = Staff(station.url, "nurse.kim", "nurse"), Staff(station.url, "nurse.kim", "nurse")
    other = Staff(station.url, "dr.lopez", "doctor")
    assert opens_ward(station.url, saved(phone)) and opens_ward(station.url, saved(desk))
    new_password = tmp_path / "pw"
    new_password.write_text("a-new-nurse-password\n")
    done = kiosk_station("passwd", "nurse.kim", "--password-file", str(new_password), "--db", ward.db_url)
    assert done.returncode == 0 and "2 login(s) ended" in done.stdout, done.stderr
    assert not opens_ward(station.url, saved(phone)) and not opens_ward(station.url, saved(desk))
    assert opens_ward(station.url, saved(other))  # someone else's login is untouched
    with pytest.raises(AssertionError):
        Staff(station.url, "nurse.kim", "nurse")  # the old password is refused
    new_login = httpx.Client(base_url=station.url, timeout=30)
    form = {
        "csrf": Staff.csrf(new_login.get("/login").text),
        "name": "nurse.kim",
        "password": "a-new-nurse-password",
        "next": "/",
    }
    assert new_login.post("/login", data=form).status_code == 303

    done = kiosk_station("remove-user", "dr.lopez", "--db", ward.db_url)
    assert done.returncode == 0 and "1 login(s) ended" in done.stdout, done.stderr
    assert not opens_ward(station.url, saved(other))
    assert opens_ward(station.url, new_login.cookies)


def test_admin_mistakes_are_one_line(db_url, tmp_path):
    make_ward(db_url)
    password = tmp_path / "pw"
    password.write_text("long-enough-password\n")
    for argv, words in (
        (["passwd", "nobody", "--password-file", str(password)], "no user 'nobody'"),
        (["remove-user", "nobody"], "no user 'nobody'"),
    ):
        done = kiosk_station(*argv, "--db", db_url)
        assert done.returncode == 2 and words in done.stderr and "Traceback" not in done.stderr
        assert len(done.stderr.strip().splitlines()) == 1


def test_a_role_change_ends_logins_and_the_cookie_holds_no_session_in_clear(db_url):
    make_ward(db_url)
    engine = db.open_database(db_url)
    session_id = logins.start(engine, "nurse.kim")
    assert logins.user_of(engine, session_id) == auth.User("nurse.kim", "nurse")
    with engine.connect() as connection:
        assert session_id not in str(connection.execute(db.staff_sessions.select()).all())
    auth.add_user(engine, "nurse.kim", "doctor", PASSWORDS["nurse"])
    assert logins.user_of(engine, session_id) is None
    assert logins.user_of(engine, "made-up") is None
    engine.dispose()


def test_a_station_made_before_0002_upgrades_and_keeps_its_users(db_url):
    from alembic import command
    from alembic.config import Config

    config = Config()
    config.set_main_option("script_location", str(db.MIGRATIONS))
    engine = db.make_engine(db_url)

    def run(step, revision: str) -> None:
        with engine.begin() as connection:
            config.attributes["connection"] = connection
            step(config, revision)

    run(command.upgrade, "0001")
    with engine.begin() as connection:
        assert "staff_sessions" not in sa.inspect(connection).get_table_names()
    auth.add_user(engine, "nurse.kim", "nurse", PASSWORDS["nurse"])  # users exist before 0002
    db.migrate(engine)
    assert auth.login(engine, "nurse.kim", PASSWORDS["nurse"], "127.0.0.1") == auth.User("nurse.kim", "nurse")
    assert logins.user_of(engine, logins.start(engine, "nurse.kim")) is not None
    run(command.downgrade, "0001")
    run(command.upgrade, "head")
    assert auth.login(engine, "nurse.kim", PASSWORDS["nurse"], "127.0.0.1") is not None
    engine.dispose()
