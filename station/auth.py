"""Who may use the station: staff (argon2-hashed passwords, roles nurse and doctor), kiosks
(bearer tokens stored as SHA-256 digests, revocable) and CSRF tokens; login throttling is
:mod:`station.throttle`, login sessions :mod:`station.logins`.

Kiosk tokens are 256-bit random strings, so a plain SHA-256 digest is enough to make a stolen
database useless for impersonating a kiosk and still lets a request find its kiosk by digest;
passwords are low-entropy, so they get argon2.
"""

from __future__ import annotations

import functools
import hashlib
import hmac
import re
import secrets

import sqlalchemy as sa
from argon2 import PasswordHasher
from argon2.exceptions import InvalidHashError, VerificationError
from sqlalchemy.engine import Connection, Engine

from basis import record
from station import db, throttle
from station.db import kiosks, settings, staff_sessions, users

ROLES = ("nurse", "doctor")
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,63}\Z")
MIN_PASSWORD = 10

_hasher = PasswordHasher()


@functools.cache
def _dummy_hash() -> str:
    """Verified against when the user does not exist, so a wrong name costs as long as a wrong
    password (made on first use: hashing is deliberately slow)."""
    return _hasher.hash("not a password of anyone")


class AuthError(ValueError):
    """An administrative request that cannot be done (message says why)."""


@record
class User:
    name: str
    role: str

    @property
    def is_doctor(self) -> bool:
        return self.role == "doctor"


def check_name(name: str, what: str) -> str:
    if not NAME.match(name):
        raise AuthError(f"{what} {name!r}: use 1-64 letters, digits, '.', '_' or '-'")
    return name


def _check_password(password: str) -> None:
    if len(password) < MIN_PASSWORD:
        raise AuthError(f"the password must have at least {MIN_PASSWORD} characters")


def add_user(engine: Engine, name: str, role: str, password: str) -> None:
    """Create a user, or set the role and password of an existing one (ending its logins)."""
    check_name(name, "user name")
    if role not in ROLES:
        raise AuthError(f"role {role!r}: choose one of {', '.join(ROLES)}")
    _check_password(password)
    values = {"role": role, "password_hash": _hasher.hash(password)}
    with engine.begin() as connection:
        if connection.execute(sa.select(users.c.name).where(users.c.name == name)).first():
            connection.execute(users.update().where(users.c.name == name).values(**values))
            end_sessions(connection, name)
        else:
            connection.execute(users.insert().values(name=name, created_at=db.now_iso(), **values))


def set_password(engine: Engine, name: str, password: str) -> int:
    """Change a user's password and end every login of that user; returns how many ended."""
    _check_password(password)
    with engine.begin() as connection:
        if not connection.execute(
            users.update().where(users.c.name == name).values(password_hash=_hasher.hash(password))
        ).rowcount:
            raise AuthError(f"no user {name!r}")
        return end_sessions(connection, name)


def remove_user(engine: Engine, name: str) -> int:
    """Delete a user and end every login of that user (what they did stays in the audit trail);
    returns how many logins ended."""
    with engine.begin() as connection:
        ended = end_sessions(connection, name)
        if not connection.execute(users.delete().where(users.c.name == name)).rowcount:
            raise AuthError(f"no user {name!r}")
    return ended


def end_sessions(connection: Connection, name: str) -> int:
    """End every login session of user ``name``, in the caller's transaction; returns how many."""
    return connection.execute(staff_sessions.delete().where(staff_sessions.c.user_name == name)).rowcount


def login(engine: Engine, name: str, password: str, address: str) -> User | None:
    """The user when the password is right, and then the failures of this name from this address
    are forgiven; None otherwise. Throttling is the caller's: :func:`station.throttle.admit`
    first (it counts the try as a failure until this proves it right)."""
    with engine.connect() as connection:
        row = connection.execute(sa.select(users.c.role, users.c.password_hash).where(users.c.name == name)).first()
    try:
        _hasher.verify(row.password_hash if row else _dummy_hash(), password)
    except (VerificationError, InvalidHashError):
        return None
    if row is None:
        return None
    with engine.begin() as connection:
        throttle.record_success(connection, name, address)
    return User(name, row.role)


def _digest(token: str) -> str:
    return hashlib.sha256(token.encode()).hexdigest()


def add_kiosk(engine: Engine, name: str) -> str:
    """Register a kiosk (or give a revoked one a new token); returns the token, shown once."""
    check_name(name, "kiosk name")
    token = secrets.token_urlsafe(32)
    with engine.begin() as connection:
        existing = connection.execute(sa.select(kiosks.c.revoked_at).where(kiosks.c.name == name)).first()
        if existing is not None and existing.revoked_at is None:
            raise AuthError(f"kiosk {name!r} already has a token; revoke it first (kiosk station revoke-kiosk {name})")
        if existing is None:
            connection.execute(kiosks.insert().values(name=name, token_hash=_digest(token), created_at=db.now_iso()))
        else:
            connection.execute(
                kiosks.update().where(kiosks.c.name == name).values(token_hash=_digest(token), revoked_at=None)
            )
    return token


def revoke_kiosk(engine: Engine, name: str) -> None:
    """Refuse the kiosk's token from now on (its data stays)."""
    with engine.begin() as connection:
        done = connection.execute(
            kiosks.update().where(kiosks.c.name == name, kiosks.c.revoked_at.is_(None)).values(revoked_at=db.now_iso())
        ).rowcount
    if not done:
        raise AuthError(f"no kiosk {name!r} with a valid token")


def kiosk_for(engine: Engine, token: str) -> str | None:
    """The kiosk a bearer token belongs to, unless revoked."""
    with engine.connect() as connection:
        return connection.execute(
            sa.select(kiosks.c.name).where(kiosks.c.token_hash == _digest(token), kiosks.c.revoked_at.is_(None))
        ).scalar()


def touch_kiosk(connection: Connection, token: str, status: str | None = None) -> str | None:
    """Authenticate a kiosk's request and note it was seen (and its new status), in one
    statement: the kiosk's name, or None for an unknown or revoked token."""
    values: dict[str, object] = {"last_seen": db.now()}
    if status is not None:
        values["status"] = status
    return connection.execute(
        kiosks.update()
        .where(kiosks.c.token_hash == _digest(token), kiosks.c.revoked_at.is_(None))
        .values(**values)
        .returning(kiosks.c.name)
    ).scalar()


def secret_key(engine: Engine) -> str:
    """The key that signs login cookies: made once, shared by every station process."""
    with engine.begin() as connection:
        value = connection.execute(sa.select(settings.c.value).where(settings.c.key == "secret_key")).scalar()
        if value is None:
            value = secrets.token_urlsafe(48)
            db.insert_ignore(connection, settings, [{"key": "secret_key", "value": value}], ["key"])
            value = connection.execute(sa.select(settings.c.value).where(settings.c.key == "secret_key")).scalar_one()
    return value


def new_csrf_token() -> str:
    return secrets.token_urlsafe(32)


def csrf_ok(expected: str | None, given: str | None) -> bool:
    if not expected or not given:
        return False
    return hmac.compare_digest(expected, given)
