"""On PostgreSQL the station runs as an app role that cannot switch off or rewrite the audit
trail: the schema's owner migrates and grants (`kiosk station migrate --grant`), the station
then works normally under the app role, and as that role disabling or dropping the append-only
trigger, UPDATE, DELETE and TRUNCATE of audit rows all fail. Real PostgreSQL, real command line,
a real station process."""

from __future__ import annotations

import uuid

import psycopg
import pytest

from station import db
from tests.station.conftest import PASSWORDS
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient
from tests.station.test_cli import kiosk_station

pytestmark = pytest.mark.slow

#: what the app role must not be able to do to the audit trail
TAMPERING = [
    "ALTER TABLE audit DISABLE TRIGGER audit_no_change",
    "ALTER TABLE audit DISABLE TRIGGER ALL",
    "DROP TRIGGER audit_no_change ON audit",
    "DROP TRIGGER audit_no_truncate ON audit",
    "DROP FUNCTION audit_append_only() CASCADE",
    "CREATE OR REPLACE FUNCTION audit_append_only() RETURNS trigger LANGUAGE plpgsql AS $$ BEGIN RETURN NEW; END $$",
    "UPDATE audit SET reason = 'nothing happened'",
    "DELETE FROM audit",
    "TRUNCATE audit",
    "DROP TABLE audit CASCADE",
    "ALTER TABLE audit RENAME TO audit_old",
    "SET session_replication_role = replica",  # would skip every trigger
]


@pytest.fixture
def roles(postgres, pg_url):
    """(owner URL, app URL, app role) on a fresh database the owner role owns."""
    suffix = uuid.uuid4().hex[:8]
    owner, app = f"station_owner_{suffix}", f"station_app_{suffix}"
    name = pg_url.rsplit("/", 1)[1]
    with psycopg.connect(postgres, autocommit=True) as connection:
        connection.execute(f"CREATE ROLE {owner} LOGIN")
        connection.execute(f"CREATE ROLE {app} LOGIN")
        connection.execute(f"ALTER DATABASE {name} OWNER TO {owner}")
    return pg_url.replace("postgres@", f"{owner}@"), pg_url.replace("postgres@", f"{app}@"), app


def one_line(done) -> str:
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    return done.stderr


def test_the_app_role_runs_the_station_and_cannot_touch_the_audit_guard(roles, station_factory, tmp_path):
    owner_url, app_url, app = roles
    # before the owner migrates, the app role is told what to run, in one line
    refused = one_line(kiosk_station("add-kiosk", "bed1", "--db", app_url))
    assert f"kiosk station migrate --db OWNER_URL --grant {app}" in refused
    done = kiosk_station("migrate", "--db", owner_url, "--grant", app)
    assert done.returncode == 0 and f"role {app}:" in done.stdout, done.stderr
    password = tmp_path / "pw"
    password.write_text(PASSWORDS["doctor"] + "\n")
    assert (
        kiosk_station(
            "add-user", "dr.lopez", "--role", "doctor", "--password-file", str(password), "--db", app_url
        ).returncode
        == 0
    )
    added = kiosk_station("add-kiosk", "ward3-bed2", "--db", app_url)
    assert added.returncode == 0, added.stderr
    token = added.stdout.strip().splitlines()[-1]

    station = station_factory(app_url)
    assert "warning" not in station.log.read_text()  # no owner powers: nothing to warn about
    kiosk = KioskClient(station.url, token, "ward3-bed2")
    rows = record_patient(PATIENTS / "barthel1.yaml")
    assert kiosk.sync(rows).status_code == 200
    session = rows[0].session_id
    doctor = Staff(station.url)
    change = doctor.post(f"/sessions/{session}/items/feeding", option="1", reason="needs help cutting food")
    assert change.status_code == 303 and "Change%20recorded" in change.headers["location"]
    assert doctor.post(f"/sessions/{session}/sign-off").status_code == 303
    assert "amended" in doctor.http.get(f"/sessions/{session}/export.csv").text
    # an alert, a command and its acknowledgement, a failed login: every table the station writes
    call_rows = record_patient(PATIENTS / "barthel5.yaml", first_seq=1000)
    call = next(r for r in call_rows if r.alert and r.payload["kind"] == "doctor_called")
    assert kiosk.sync([r for r in call_rows if r.seq <= call.seq]).status_code == 200
    assert doctor.post("/kiosks/ward3-bed2/command", session_id=call.session_id, kind="continue").status_code == 303
    (command,) = kiosk.commands()
    assert kiosk.ack(command["id"]).status_code == 200
    assert doctor.post("/logout").status_code == 303
    assert (
        doctor.http.post(
            "/login",
            data={"csrf": Staff.csrf(doctor.http.get("/login").text), "name": "dr.lopez", "password": "wrong-password"},
        ).status_code
        == 401
    )
    kiosk.close()
    assert kiosk_station("remove-user", "dr.lopez", "--db", app_url).returncode == 0

    with psycopg.connect(owner_url) as connection:
        trail = connection.execute("SELECT * FROM audit ORDER BY id").fetchall()
    assert [row[4] for row in trail] == ["correct", "sign_off", "command"]
    for statement in TAMPERING:
        with psycopg.connect(app_url) as connection:
            with pytest.raises(psycopg.errors.InsufficientPrivilege, match="permission denied|must be owner"):
                connection.execute(statement)
    with psycopg.connect(app_url, autocommit=True) as connection:
        connection.execute("GRANT UPDATE, DELETE, TRUNCATE ON audit TO PUBLIC")  # a warning, nothing granted
        assert connection.execute(
            "SELECT has_table_privilege('audit', 'UPDATE') OR has_table_privilege('audit', "
            "'DELETE') OR has_table_privilege('audit', 'TRUNCATE')"
        ).fetchone() == (False,)
    with psycopg.connect(owner_url) as connection:
        assert connection.execute("SELECT * FROM audit ORDER BY id").fetchall() == trail
        enabled = dict(
            connection.execute(
                "SELECT tgname, tgenabled FROM pg_trigger WHERE tgrelid = 'audit'::regclass AND NOT tgisinternal"
            ).fetchall()
        )
    assert enabled == {"audit_no_change": "O", "audit_no_truncate": "O"}


def test_running_as_the_owner_warns_and_grant_mistakes_are_one_line(roles, station_factory, tmp_path):
    owner_url, app_url, app = roles
    assert "--grant is for PostgreSQL" in one_line(
        kiosk_station("migrate", "--db", db.sqlite_url(tmp_path / "d"), "--grant", app)
    )
    assert "no role 'nobody_here'" in one_line(kiosk_station("migrate", "--db", owner_url, "--grant", "nobody_here"))
    owner = owner_url.rsplit("@", 1)[0].rsplit("/", 1)[1]
    assert "owns the tables" in one_line(kiosk_station("migrate", "--db", owner_url, "--grant", owner))
    assert kiosk_station("migrate", "--db", owner_url, "--grant", app).returncode == 0
    # the owner upgraded (here: a new table) without granting it: the app role is told, in one line
    with psycopg.connect(owner_url, autocommit=True) as connection:
        connection.execute(f"REVOKE ALL ON staff_sessions FROM {app}")
    assert "may not SELECT on table staff_sessions" in one_line(kiosk_station("--db", app_url))
    assert kiosk_station("migrate", "--db", owner_url, "--grant", app).returncode == 0
    assert "only the tables' owner" in one_line(kiosk_station("migrate", "--db", app_url, "--grant", app))
    station = station_factory(owner_url)
    assert "could switch off the audit trail's append-only guard" in station.log.read_text()
