"""Staff login sessions, kept on the server so they can be ended: the login cookie (signed) holds
only a random session id; the database holds its SHA-256 digest, the user and when it expires.

Logging out ends that session; a password change, a role change or the user's removal ends every
session of that user (:func:`station.auth.end_sessions`), so a cookie saved before any of these opens nothing.
Every station process behind one database sees the same sessions.
"""

from __future__ import annotations

import hashlib
import secrets

import sqlalchemy as sa
from sqlalchemy.engine import Engine

from station import db
from station.auth import User
from station.db import staff_sessions, users

#: a login lasts one long shift at most (the cookie's max-age is the same)
MAX_AGE_S = 12 * 3600


def _digest(session_id: str) -> str:
    return hashlib.sha256(session_id.encode()).hexdigest()


def start(engine: Engine, name: str) -> str:
    """A new session for user ``name``; returns its id (goes in the cookie, nowhere else)."""
    session_id = secrets.token_urlsafe(32)
    now = db.now()
    with engine.begin() as connection:
        connection.execute(staff_sessions.delete().where(staff_sessions.c.expires_at < now))
        connection.execute(
            staff_sessions.insert().values(
                id_hash=_digest(session_id), user_name=name, created_at=now, expires_at=now + MAX_AGE_S
            )
        )
    return session_id


def user_of(engine: Engine, session_id: str) -> User | None:
    """The user of a live session; None when it was ended, expired or never existed."""
    with engine.connect() as connection:
        row = connection.execute(
            sa.select(users.c.name, users.c.role)
            .join(staff_sessions, staff_sessions.c.user_name == users.c.name)
            .where(staff_sessions.c.id_hash == _digest(session_id), staff_sessions.c.expires_at > db.now())
        ).first()
    return User(row.name, row.role) if row else None


def end(engine: Engine, session_id: str) -> None:
    """End one session (logout); ending an unknown one is not an error."""
    with engine.begin() as connection:
        connection.execute(staff_sessions.delete().where(staff_sessions.c.id_hash == _digest(session_id)))
