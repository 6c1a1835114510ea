"""The station's tables and database: SQLite by default, PostgreSQL for a hospital.

The schema is owned by Alembic (``station/migrations``), run at every start; the tables here
mirror it for queries. What a kiosk sends is kept as it came (:data:`inbox`, one row per outbox
row, unique on ``(kiosk_id, seq)``) and a session is read back by folding its rows in ``seq``
order (:mod:`station.sessions`), so a row that arrives late (alerts go first) takes its place
without rewriting anything. The audit trail refuses UPDATE and DELETE in the database itself
(triggers created by the migration), not only in this code.
"""

from __future__ import annotations

import os
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import sqlalchemy as sa
from alembic import command
from alembic.config import Config
from sqlalchemy.engine import Connection, Engine

DB_NAME = "station.sqlite3"
MIGRATIONS = Path(__file__).with_name("migrations")

metadata = sa.MetaData()

settings = sa.Table(
    "settings",
    metadata,
    sa.Column("key", sa.String(64), primary_key=True),
    sa.Column("value", sa.Text, nullable=False),
)

users = sa.Table(
    "users",
    metadata,
    sa.Column("name", sa.String(64), primary_key=True),
    sa.Column("role", sa.String(16), nullable=False),
    sa.Column("password_hash", sa.Text, nullable=False),
    sa.Column("created_at", sa.String(40), nullable=False),
)

staff_sessions = sa.Table(
    "staff_sessions",
    metadata,
    sa.Column("id_hash", sa.String(64), primary_key=True),
    sa.Column("user_name", sa.String(64), sa.ForeignKey("users.name", ondelete="CASCADE"), nullable=False),
    sa.Column("created_at", sa.Float, nullable=False),
    sa.Column("expires_at", sa.Float, nullable=False),
)

login_failures = sa.Table(
    "login_failures",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("name", sa.String(64), nullable=False),
    sa.Column("address", sa.String(64), nullable=False),
    sa.Column("at", sa.Float, nullable=False),
)

kiosks = sa.Table(
    "kiosks",
    metadata,
    sa.Column("name", sa.String(64), primary_key=True),
    sa.Column("token_hash", sa.String(64), nullable=False, unique=True),
    sa.Column("created_at", sa.String(40), nullable=False),
    sa.Column("revoked_at", sa.String(40)),
    #: epoch seconds of the last request the kiosk made (status, sync or poll)
    sa.Column("last_seen", sa.Float),
    #: the latest live status (protocol §2) as JSON
    sa.Column("status", sa.Text),
)

inbox = sa.Table(
    "inbox",
    metadata,
    sa.Column("kiosk_id", sa.String(64), primary_key=True),
    sa.Column("seq", sa.BigInteger, primary_key=True),
    sa.Column("kind", sa.String(64), nullable=False),
    sa.Column("session_id", sa.String(64), nullable=False, index=True),
    sa.Column("payload", sa.Text, nullable=False),
    sa.Column("at", sa.String(40), nullable=False),
    sa.Column("received_at", sa.Float, nullable=False),
)

sessions = sa.Table(
    "sessions",
    metadata,
    sa.Column("id", sa.String(64), primary_key=True),
    sa.Column("kiosk_id", sa.String(64), nullable=False),
    sa.Column("patient_id", sa.String(64)),
    sa.Column("started_at", sa.String(40)),
    sa.Column("status", sa.String(16), nullable=False),
    sa.Column("finished_at", sa.String(40)),
    sa.Column("updated_at", sa.Float, nullable=False),
    #: the definition the session ran (its kiosk sent it with create_session), by content address
    sa.Column("definition_sha256", sa.String(64)),
    #: the definition was attached by the station (an upgrade, or a kiosk that sent none): the bundled one
    sa.Column("definition_attached_later", sa.Boolean, nullable=False, server_default=sa.false()),
    #: when the sign-off the result stands under was made; NULL while it waits for validation
    #: (never signed, or reopened to amend): written with the audit row that changes it
    sa.Column("signed_at", sa.String(40)),
)

#: questionnaire definitions, stored once per content (kiosk.core.questionnaire.definition: canonical JSON, SHA-256)
definitions = sa.Table(
    "definitions",
    metadata,
    sa.Column("sha256", sa.String(64), primary_key=True),
    sa.Column("questionnaire_id", sa.Text, nullable=False),
    sa.Column("version", sa.Text, nullable=False),
    sa.Column("body", sa.Text, nullable=False),
    sa.Column("stored_at", sa.String(40), nullable=False),
    #: who made the station know it (station.known): "shipped", "registered by NAME", a doctor
    sa.Column("known_by", sa.String(64)),
    sa.Column("known_at", sa.String(40)),
)

alerts = sa.Table(
    "alerts",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("kiosk_id", sa.String(64), nullable=False),
    sa.Column("seq", sa.BigInteger, nullable=False),
    sa.Column("session_id", sa.String(64), nullable=False),
    #: "doctor_called", "person_lost" (away as long as the kiosk's site says) or "unattended"
    sa.Column("kind", sa.String(32), nullable=False),
    sa.Column("raised_at", sa.String(40), nullable=False),
    sa.Column("received_at", sa.Float, nullable=False),
    #: when the kiosk reported the matching end (doctor continued, patient back)
    sa.Column("resolved_at", sa.String(40)),
    sa.Column("ack_by", sa.String(64)),
    sa.Column("ack_at", sa.String(40)),
    sa.UniqueConstraint("kiosk_id", "seq"),
)

commands = sa.Table(
    "commands",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("kiosk_id", sa.String(64), nullable=False, index=True),
    sa.Column("session_id", sa.String(64), nullable=False),
    sa.Column("kind", sa.String(16), nullable=False),
    sa.Column("by", sa.String(64), nullable=False),
    sa.Column("at", sa.String(40), nullable=False),
    sa.Column("acked_at", sa.String(40)),
    sa.Column("result", sa.String(16)),
    sa.Column("reason", sa.Text),
)

audit = sa.Table(
    "audit",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("session_id", sa.String(64), index=True),
    sa.Column("at", sa.String(40), nullable=False),
    sa.Column("author", sa.String(64), nullable=False),
    #: correct, fill, sign_off, acknowledge, command
    sa.Column("action", sa.String(16), nullable=False),
    sa.Column("item_id", sa.String(64)),
    sa.Column("option", sa.Integer),
    sa.Column("previous_option", sa.Integer),
    sa.Column("reason", sa.Text, nullable=False, server_default=""),
)


class DatabaseError(RuntimeError):
    """The database cannot be opened or migrated (message says which and why)."""


#: visits staff ordered for a kiosk (station.orders owns their states)
orders = sa.Table(
    "orders",
    metadata,
    sa.Column("id", sa.String(32), primary_key=True),
    sa.Column("kiosk_id", sa.String(64), nullable=False),
    sa.Column("patient_id", sa.String(64), nullable=False),
    #: JSON list of questionnaire ids, in the order the kiosk gives them
    sa.Column("instruments", sa.Text, nullable=False),
    sa.Column("language", sa.String(8), nullable=False),
    sa.Column("answered_by", sa.String(16), nullable=False),
    sa.Column("code", sa.String(8), nullable=False),
    sa.Column("state", sa.String(24), nullable=False),
    sa.Column("ordered_by", sa.String(64), nullable=False),
    sa.Column("ordered_at", sa.String(40), nullable=False),
    sa.Column("session_id", sa.String(64)),
    sa.Column("updated_at", sa.String(40), nullable=False),
    #: how the person answering is related to the patient (kiosk.core.answerers), None: not said
    sa.Column("relationship", sa.String(16)),
    #: the relationship in words, for "other" only (at most 60 characters)
    sa.Column("relationship_text", sa.String(60)),
)

#: how each session at the station began: "order" (with its order), "staff" (started by staff at the
#: kiosk for a patient id they typed) or "walk-up" (whoever tapped the welcome, where allowed)
visits = sa.Table(
    "visits",
    metadata,
    sa.Column("session_id", sa.String(64), primary_key=True),
    sa.Column("kind", sa.String(16), nullable=False),
    sa.Column("order_id", sa.String(32)),
)

#: a clinician's own answers for a session's items (a validation study, station.reference): apart
#: from what the kiosk sent, append-only (a change is a newer row; the latest per item counts)
reference_results = sa.Table(
    "reference_results",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("session_id", sa.String(64), nullable=False),
    sa.Column("questionnaire_id", sa.String(64), nullable=False),
    sa.Column("item_id", sa.String(64), nullable=False),
    sa.Column("option", sa.Integer, nullable=False),
    sa.Column("entered_by", sa.String(64), nullable=False),
    sa.Column("entered_at", sa.String(40), nullable=False),
)

#: Timed Up and Go results (station.tugs), one per record_tug row a kiosk sent
tug_results = sa.Table(
    "tug_results",
    metadata,
    sa.Column("id", sa.String(64), primary_key=True),
    sa.Column("kiosk_id", sa.String(64), nullable=False),
    sa.Column("seq", sa.BigInteger, nullable=False),
    sa.Column("patient_id", sa.String(64), nullable=False),
    sa.Column("at", sa.String(40), nullable=False),
    #: how the visit began ("order", "staff"), and its order; None: the kiosk did not say
    sa.Column("visit_kind", sa.String(16)),
    sa.Column("order_id", sa.String(32)),
    #: the kiosk's visit (a battery's id), which its questionnaire sessions name in their log
    sa.Column("visit_id", sa.String(64)),
    sa.Column("confirmed_by", sa.String(64), nullable=False),
    #: accepted (the camera's time), stopwatch (staff's time), rejected (no time)
    sa.Column("decision", sa.String(16), nullable=False),
    sa.Column("decided_by", sa.String(64), nullable=False),
    sa.Column("total_s", sa.Float),
    sa.Column("method", sa.String(16)),
    sa.Column("camera_total_s", sa.Float),
    sa.Column("threshold_s", sa.Float, nullable=False),
    #: JSON: [{"name", "start_t", "end_t"}], and the analysis' reasons (text list)
    sa.Column("phases", sa.Text, nullable=False),
    sa.Column("reasons", sa.Text, nullable=False),
    sa.Column("person_share", sa.Float, nullable=False),
    sa.Column("body_cut_off", sa.Boolean, nullable=False),
    sa.Column("turn_seen", sa.Boolean, nullable=False),
    sa.Column("get_up_go", sa.Integer),
    sa.Column("walking_aid", sa.String(16)),
    sa.Column("simulated", sa.Boolean, nullable=False, server_default=sa.false()),
    #: the kiosk's export identity (JSON), as a create_session's
    sa.Column("export", sa.Text),
    sa.Column("received_at", sa.Float, nullable=False),
    sa.UniqueConstraint("kiosk_id", "seq"),
)

code_failures = sa.Table(
    "order_code_failures",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("kiosk_id", sa.String(64), nullable=False),
    sa.Column("at", sa.Float, nullable=False),
)


def now_iso() -> str:
    """The wall-clock time, ISO-8601 UTC, as every stored time."""
    return datetime.now(UTC).isoformat(timespec="milliseconds")


def now() -> float:
    """Epoch seconds (for last-seen and rate-limit windows)."""
    return time.time()


def default_data_dir() -> Path:
    """``$KIOSK_STATION_DIR``, else the user's data directory for the station."""
    from platformdirs import user_data_dir

    return Path(os.environ.get("KIOSK_STATION_DIR") or user_data_dir("kiosk-station", appauthor=False))


def sqlite_url(data_dir: Path) -> str:
    """The default database: one SQLite file in ``data_dir`` (directory 0700, file 0600)."""
    data_dir.mkdir(mode=0o700, parents=True, exist_ok=True)
    os.chmod(data_dir, 0o700)
    return private_sqlite(data_dir / DB_NAME)


def private_sqlite(path: Path) -> str:
    """The URL of a SQLite file made owner-only before SQLite opens it (SQLite gives its WAL and
    SHM files the database file's mode); a directory made for it is 0700."""
    path = path.expanduser()
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o600)
    os.close(fd)
    os.chmod(path, 0o600)
    return f"sqlite:///{path}"


def _normalise(url: str) -> str:
    """``postgresql://`` means psycopg 3 (SQLAlchemy's default driver name is psycopg2)."""
    for prefix in ("postgresql://", "postgres://"):
        if url.startswith(prefix):
            return "postgresql+psycopg://" + url[len(prefix) :]
    return url


def make_engine(url: str) -> Engine:
    """An engine for ``url``; SQLite in WAL mode with foreign keys and a busy timeout, so the
    web threads and a long poll share it."""
    url = _normalise(url)
    try:
        return _make_engine(url)
    except (sa.exc.ArgumentError, ImportError):  # not a URL, or a database the station does not run on
        raise DatabaseError(
            f"--db {url!r}: not a station database URL (postgresql://user@host/dbname or sqlite:///path)"
        ) from None


def _make_engine(url: str) -> Engine:
    if url.startswith("sqlite"):
        engine = sa.create_engine(url, connect_args={"timeout": 30, "check_same_thread": False})

        @sa.event.listens_for(engine, "connect")
        def _pragmas(dbapi_connection, _record):  # SQLAlchemy's hook signature
            cursor = dbapi_connection.cursor()
            cursor.execute("PRAGMA journal_mode=WAL")
            cursor.execute("PRAGMA synchronous=FULL")
            cursor.execute("PRAGMA foreign_keys=ON")
            cursor.close()

        return engine
    # more connections than the web's 40 worker threads, so a worker never waits for one
    return sa.create_engine(url, pool_size=20, max_overflow=30, pool_pre_ping=True)


def is_postgres(engine: Engine) -> bool:
    return engine.dialect.name == "postgresql"


def insert_ignore(connection: Connection, table: sa.Table, rows: list[dict[str, Any]], keys: list[str]) -> None:
    """INSERT ... ON CONFLICT DO NOTHING on either engine (a concurrent retry is not an error)."""
    if not rows:
        return
    if connection.dialect.name == "postgresql":
        from sqlalchemy.dialects.postgresql import insert as postgresql_insert

        connection.execute(postgresql_insert(table).on_conflict_do_nothing(index_elements=keys), rows)
    else:
        from sqlalchemy.dialects.sqlite import insert as sqlite_insert

        connection.execute(sqlite_insert(table).on_conflict_do_nothing(index_elements=keys), rows)


def migrate(engine: Engine) -> None:
    """Bring the schema to the newest Alembic revision. On PostgreSQL an advisory lock makes
    several station processes starting together migrate one after the other; a schema already
    current needs no privilege beyond reading ``alembic_version``, so an app role
    (:mod:`station.roles`) starts a station the owner has migrated."""
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    try:
        with engine.begin() as connection:
            if is_postgres(engine):
                connection.execute(sa.text("SELECT pg_advisory_xact_lock(727274)"))
            config.attributes["connection"] = connection
            command.upgrade(config, "head")
    except sa.exc.SQLAlchemyError as exc:
        if getattr(getattr(exc, "orig", None), "sqlstate", None) == "42501":  # insufficient privilege
            role = engine.url.username or "this role"
            raise DatabaseError(
                f"the station database {engine.url.render_as_string()} needs migrating, and role "
                f"{role!r} may not change its schema: run 'kiosk station migrate --db OWNER_URL "
                f"--grant {role}' as the schema's owner first"
            ) from None
        raise DatabaseError(
            f"cannot open the station database {engine.url!r}: {exc.__class__.__name__}: {str(exc).splitlines()[0]}"
        ) from None


def open_database(url: str) -> Engine:
    """An engine on ``url`` with the schema migrated to the newest revision."""
    engine = make_engine(url)
    migrate(engine)
    return engine
