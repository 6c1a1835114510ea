"""The station's database on both engines: Alembic migrations, the append-only audit trail in the
database itself, validation producing the Review exports take, and a session refused to a
second kiosk. PostgreSQL is the real server started by the shared fixture."""

from __future__ import annotations

import pytest
import sqlalchemy as sa
from alembic.config import Config
from alembic.runtime.migration import MigrationContext
from alembic.script import ScriptDirectory

from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.review import ReviewState
from station import auth, db, sync, validation
from station.auth import User
from station.sessions import load
from tests.station.helpers import PATIENTS, record_patient


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request, tmp_path):
    url = db.sqlite_url(tmp_path / "data") if request.param == "sqlite" else request.getfixturevalue("pg_url")
    engine = db.open_database(url)
    yield engine
    engine.dispose()


def _ingest(engine, script: str, kiosk: str = "bed1"):
    rows = record_patient(PATIENTS / script)
    with engine.begin() as connection:
        stored, _ = sync.intake(connection, kiosk, sync.parse({"events": [r.event() for r in rows]}))
    assert stored == [r.seq for r in rows]
    return rows


def test_migrations_reach_the_newest_revision_and_running_them_again_changes_nothing(engine):
    config = Config()
    config.set_main_option("script_location", str(db.MIGRATIONS))
    head = ScriptDirectory.from_config(config).get_current_head()
    db.migrate(engine)
    with engine.connect() as connection:
        assert MigrationContext.configure(connection).get_current_revision() == head
        assert set(sa.inspect(connection).get_table_names()) >= {"inbox", "audit", "alerts", "commands", "users"}


def test_the_audit_trail_refuses_update_and_delete_in_the_database_itself(engine):
    rows = _ingest(engine, "barthel1.yaml")
    q = load_questionnaire()
    validation.change_item(
        engine, q, rows[0].session_id, "feeding", 1, "patient needs help cutting food", User("nurse.kim", "nurse")
    )
    for statement in (db.audit.update().values(reason="nothing happened"), db.audit.delete()):
        with pytest.raises(sa.exc.DatabaseError, match="append-only"):
            with engine.begin() as connection:
                connection.execute(statement)
    assert [e.reason for e in validation.trail(engine, rows[0].session_id)] == ["patient needs help cutting food"]


def test_corrections_keep_the_recorded_answer_and_only_a_doctor_signs_off(engine):
    rows = _ingest(engine, "barthel1.yaml")
    session_id = rows[0].session_id
    q = load_questionnaire()
    nurse, doctor = User("nurse.kim", "nurse"), User("dr.lopez", "doctor")
    recorded = next(r.payload["option"] for r in rows if r.kind == "record_answer" and r.payload["item_id"] == "stairs")
    new = 1 if recorded != 1 else 2
    validation.change_item(engine, q, session_id, "stairs", new, "confirmed with the physiotherapist", nurse)
    with pytest.raises(validation.ValidationError, match="only a doctor"):
        validation.sign_off(engine, session_id, nurse)
    with pytest.raises(validation.ValidationError, match="needs a reason"):
        validation.change_item(engine, q, session_id, "bathing", 1, "   ", doctor)
    validation.sign_off(engine, session_id, doctor)
    review = validation.review(engine, session_id)
    assert review.state is ReviewState.AMENDED and review.signed_by == "dr.lopez"
    (change,) = review.corrections
    assert (change.item_id, change.option, change.previous_option, change.author) == (
        "stairs",
        new,
        recorded,
        "nurse.kim",
    )
    with pytest.raises(validation.ValidationError, match="final"):
        validation.change_item(engine, q, session_id, "stairs", recorded, "changed my mind", doctor)
    actions = [e.action for e in validation.trail(engine, session_id)]
    assert actions == ["correct", "sign_off"]


def test_an_unanswered_item_is_filled_and_a_running_session_cannot_be_validated(engine):
    rows = _ingest(engine, "barthel3.yaml")
    session_id = rows[0].session_id
    q = load_questionnaire()
    doctor = User("dr.lopez", "doctor")
    unanswered = [r.payload["item_id"] for r in rows if r.kind == "record_not_answered"]
    if unanswered:
        validation.change_item(engine, q, session_id, unanswered[0], 1, "asked at the bedside", doctor)
        assert validation.review(engine, session_id).corrections[0].previous_option is None
    running = record_patient(PATIENTS / "barthel1.yaml", first_seq=1000)
    cut = [r for r in running if r.kind != "finish_session"]
    with engine.begin() as connection:
        sync.intake(connection, "bed1", sync.parse({"events": [r.event() for r in cut]}))
    with pytest.raises(validation.ValidationError, match="running"):
        validation.sign_off(engine, running[0].session_id, doctor)


def test_kiosk_tokens_are_stored_hashed_and_revocable(engine):
    token = auth.add_kiosk(engine, "bed7")
    with engine.connect() as connection:
        assert token not in str(connection.execute(sa.select(db.kiosks)).all())
    assert auth.kiosk_for(engine, token) == "bed7"
    with pytest.raises(auth.AuthError, match="already has a token"):
        auth.add_kiosk(engine, "bed7")
    auth.revoke_kiosk(engine, "bed7")
    assert auth.kiosk_for(engine, token) is None
    fresh = auth.add_kiosk(engine, "bed7")
    assert auth.kiosk_for(engine, fresh) == "bed7" and auth.kiosk_for(engine, token) is None


def test_passwords_are_argon2_hashed(engine):
    auth.add_user(engine, "dr.lopez", "doctor", "a-long-password")
    with engine.connect() as connection:
        stored = connection.execute(sa.select(db.users.c.password_hash)).scalar_one()
    assert stored.startswith("$argon2") and "a-long-password" not in stored
    assert auth.login(engine, "dr.lopez", "a-long-password", "127.0.0.1") == User("dr.lopez", "doctor")
    assert auth.login(engine, "dr.lopez", "wrong-password", "127.0.0.1") is None
    with pytest.raises(auth.AuthError, match="at least"):
        auth.add_user(engine, "nurse.kim", "nurse", "short")


def test_a_withdrawn_answer_is_gone_and_the_session_follows_interruption_and_continuation(engine):
    rows = record_patient(PATIENTS / "barthel1.yaml")
    session_id = rows[0].session_id
    first = next(r for r in rows if r.kind == "record_answer")
    item = first.payload["item_id"]
    seq = rows[-1].seq
    extra = [  # the patient changed that answer, the kiosk died, staff continued the test elsewhere
        {
            "seq": seq + 1,
            "kind": "withdraw_answer",
            "session_id": session_id,
            "at": first.at,
            "payload": {"item_id": item, "t": first.t + 1, "at": first.at, "reason": "patient: change my answer"},
        },
        {
            "seq": seq + 2,
            "kind": "mark_interrupted",
            "session_id": session_id,
            "at": first.at,
            "payload": {"reason": "the kiosk stopped"},
        },
    ]
    events = [r.event() for r in rows if r.kind != "finish_session"] + extra
    with engine.begin() as connection:
        sync.intake(connection, "bed1", sync.parse({"events": events}))
        stored = load(connection, session_id)[1]
    assert item not in {a.item_id for a in stored.answers}
    assert stored.status == "interrupted" and stored.interrupted_reason == "the kiosk stopped"
    again = {"seq": seq + 3, "kind": "continue_session", "session_id": session_id, "at": first.at, "payload": {}}
    answer = {
        "seq": seq + 4,
        "kind": "record_answer",
        "session_id": session_id,
        "at": first.at,
        "payload": first.payload | {"option": 1, "points": load_questionnaire().item(item).option(1).points},
    }
    with engine.begin() as connection:
        sync.intake(connection, "bed1", sync.parse({"events": [again, answer]}))
        stored = load(connection, session_id)[1]
        listed = connection.execute(sa.select(db.sessions.c.status).where(db.sessions.c.id == session_id)).scalar()
    assert stored.status == listed == "running" and stored.interrupted_reason is None
    assert {a.item_id: a.option for a in stored.answers}[item] == 1
    assert not [e for e in stored.log if e.kind.startswith("unrecognised")]
