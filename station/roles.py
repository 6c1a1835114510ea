"""PostgreSQL roles: the schema's owner migrates, the station runs as an app role that cannot
touch the audit trail's guard.

The owner of a table may disable or drop its triggers, so a station running as the owner could
switch off the append-only audit trail and rewrite it. ``kiosk station migrate --db OWNER_URL
--grant APP_ROLE`` migrates as the owner and gives the app role SELECT, INSERT, UPDATE and
DELETE on the station's tables, only SELECT and INSERT on ``audit``, SELECT on
``alembic_version`` (to see the schema is current) and the sequences' USAGE; never ownership,
TRUNCATE, TRIGGER or REFERENCES. SQLite has no roles: one owner-only file, as before.
"""

from __future__ import annotations

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from station import db

#: the only privileges the app role gets on the audit trail
AUDIT_PRIVILEGES = "SELECT, INSERT"
APP_PRIVILEGES = "SELECT, INSERT, UPDATE, DELETE"


class RoleError(ValueError):
    """A grant that cannot be done (message says why)."""


def _quote(connection: Connection, name: str) -> str:
    return connection.dialect.identifier_preparer.quote(name)


def grant_app_role(engine: Engine, role: str) -> None:
    """Give ``role`` what the station needs and nothing that could weaken the audit trail
    (run as the schema's owner, after :func:`station.db.migrate`; running it again is harmless)."""
    if not db.is_postgres(engine):
        raise RoleError("--grant is for PostgreSQL: a SQLite station is one owner-only file, with no roles")
    try:
        _grant(engine, role)
    except sa.exc.SQLAlchemyError as exc:
        raise RoleError(
            f"cannot grant role {role!r} the station's tables: {str(getattr(exc, 'orig', None) or exc).splitlines()[0]}"
        ) from None


def _grant(engine: Engine, role: str) -> None:
    with engine.begin() as connection:
        if not connection.execute(sa.text("SELECT 1 FROM pg_roles WHERE rolname = :r"), {"r": role}).first():
            raise RoleError(f"no role {role!r} on this server: create it first (CREATE ROLE {role} LOGIN PASSWORD ...)")
        if connection.execute(sa.text("SELECT rolsuper FROM pg_roles WHERE rolname = :r"), {"r": role}).scalar():
            raise RoleError(
                f"role {role!r} is a superuser, so it can change anything: give the station an ordinary role"
            )
        owner = connection.execute(
            sa.text("SELECT tableowner FROM pg_tables WHERE tablename = 'audit' AND schemaname = current_schema()")
        ).scalar()
        if owner == role:
            raise RoleError(f"role {role!r} owns the tables: the app role must be another role than the owner")
        me, superuser = connection.execute(
            sa.text("SELECT current_user, rolsuper FROM pg_roles WHERE rolname = current_user")
        ).one()
        if me != owner and not superuser:  # PostgreSQL would only warn, and grant nothing
            raise RoleError(
                f"only the tables' owner ({owner!r}) can grant them; this is role {me!r}: give the owner's URL as --db"
            )
        who, schema = (
            _quote(connection, role),
            _quote(connection, connection.execute(sa.text("SELECT current_schema()")).scalar_one()),
        )
        app_tables = [name for name in db.metadata.tables if name != db.audit.name]
        connection.execute(sa.text(f"GRANT USAGE ON SCHEMA {schema} TO {who}"))
        for table in [*app_tables, db.audit.name, "alembic_version"]:
            connection.execute(sa.text(f"REVOKE ALL ON {schema}.{_quote(connection, table)} FROM {who}"))
        for table in app_tables:
            connection.execute(sa.text(f"GRANT {APP_PRIVILEGES} ON {schema}.{_quote(connection, table)} TO {who}"))
        audit = f"{schema}.{_quote(connection, db.audit.name)}"
        connection.execute(sa.text(f"GRANT {AUDIT_PRIVILEGES} ON {audit} TO {who}"))
        connection.execute(sa.text(f"GRANT SELECT ON {schema}.alembic_version TO {who}"))
        connection.execute(sa.text(f"GRANT USAGE ON ALL SEQUENCES IN SCHEMA {schema} TO {who}"))


def check_privileges(engine: Engine) -> None:
    """On PostgreSQL, refuse to run (DatabaseError, one sentence) when the station's role lacks a
    privilege it needs on a table, as after an upgrade the owner migrated without ``--grant``:
    better than an error on the first request that touches that table."""
    if not db.is_postgres(engine):
        return
    needed = {name: APP_PRIVILEGES for name in db.metadata.tables} | {db.audit.name: AUDIT_PRIVILEGES}
    with engine.connect() as connection:
        for table, privileges in needed.items():
            for privilege in privileges.split(", "):
                if not connection.execute(
                    sa.text("SELECT has_table_privilege(:t, :p)"), {"t": table, "p": privilege}
                ).scalar():
                    role = connection.execute(sa.text("SELECT current_user")).scalar()
                    raise db.DatabaseError(
                        f"role {role!r} may not {privilege} on table {table}: run 'kiosk station migrate --db "
                        f"OWNER_URL --grant {role}' as the schema's owner"
                    )


def guard_warning(engine: Engine) -> str | None:
    """A sentence for the operator when the station's own role could switch the audit trail's
    guard off (it owns ``audit`` or is a superuser); None on SQLite or under an app role."""
    if not db.is_postgres(engine):
        return None
    with engine.connect() as connection:
        row = connection.execute(
            sa.text(
                "SELECT current_user AS me, (SELECT rolsuper FROM pg_roles WHERE rolname = current_user) AS super, "
                "(SELECT tableowner FROM pg_tables WHERE tablename = 'audit' AND schemaname = current_schema()) "
                "AS owner"
            )
        ).one()
    if not row.super and row.owner != row.me:
        return None
    return (
        f"warning: the station runs as role {row.me!r}, which "
        f"{'is a superuser' if row.super else 'owns the audit table'} and could switch off the audit "
        "trail's append-only guard; run it as an app role (kiosk station migrate --db OWNER_URL --grant ROLE)"
    )
