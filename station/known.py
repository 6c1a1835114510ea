"""The instrument definitions this station knows, by SHA-256 of their canonical JSON: the ones
shipped with it (registered at every start), the ones staff register from a file
(``kiosk station add-definition FILE``), and the ones a doctor approves on a session's page.

A kiosk sends the definition its session runs; one this station does not know is stored and its
session shown, but its total formula -- the one part of a definition that is code -- is run by
nobody until it is known (:mod:`station.formulas`): its results say that they wait for a
doctor's approval. A definition whose total is a sum of the points it declares runs nothing, and
is scored as it comes.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from kiosk.core.questionnaire import bundled_path, load_questionnaire
from kiosk.core.questionnaire.definition import canonical, canonical_json, digest
from station import db
from station.db import audit, definitions

#: the instrument files shipped with the kiosk and its station
SHIPPED = bundled_path().parent


class KnownError(ValueError):
    """A definition that cannot be made known (message says why)."""


def known(connection: Connection, shas: Iterable[str]) -> set[str]:
    """Which of ``shas`` this station knows (one query)."""
    wanted = sorted({s for s in shas if s})
    if not wanted:
        return set()
    query = sa.select(definitions.c.sha256).where(definitions.c.sha256.in_(wanted), definitions.c.known_at.is_not(None))
    return set(connection.execute(query).scalars())


def register(connection: Connection, definition: Mapping[str, Any], by: str) -> str:
    """Store ``definition`` (if new) and make it known in the name of ``by``; returns its hash."""
    sha = digest(definition)
    now = db.now_iso()
    db.insert_ignore(
        connection,
        definitions,
        [
            {
                "sha256": sha,
                "questionnaire_id": str(definition.get("id", "")),
                "version": str(definition.get("version", "")),
                "body": canonical_json(definition),
                "stored_at": now,
            }
        ],
        ["sha256"],
    )
    connection.execute(
        definitions.update()
        .where(definitions.c.sha256 == sha, definitions.c.known_at.is_(None))
        .values(known_by=by[:64], known_at=now)
    )
    return sha


def register_file(engine: Engine, path: Path, by: str) -> tuple[str, str]:
    """Register the instrument file at ``path`` (checked as the kiosk checks it); returns its id
    and hash."""
    q = load_questionnaire(path)
    with engine.begin() as connection:
        return q.id, register(connection, canonical(q), f"registered by {by}")


def register_shipped(engine: Engine) -> list[str]:
    """Make the instruments shipped with this station known (run at every start: an upgrade
    ships new versions). Returns their hashes."""
    found = [canonical(load_questionnaire(path)) for path in sorted(SHIPPED.glob("*.yaml"))]
    with engine.begin() as connection:
        already = known(connection, [digest(d) for d in found])
        return [register(connection, d, "shipped") if digest(d) not in already else digest(d) for d in found]


def approve(engine: Engine, sha: str, by: Any) -> None:
    """A doctor approves a definition a kiosk sent (recorded in the audit trail)."""
    if not by.is_doctor:
        raise KnownError("only a doctor can approve a questionnaire definition")
    with engine.begin() as connection:
        row = connection.execute(
            sa.select(definitions.c.questionnaire_id, definitions.c.version, definitions.c.known_by).where(
                definitions.c.sha256 == sha
            )
        ).first()
        if row is None:
            raise KnownError(f"no definition {sha[:12]} has reached this station")
        if row.known_by is not None:
            return
        connection.execute(
            definitions.update()
            .where(definitions.c.sha256 == sha, definitions.c.known_at.is_(None))
            .values(known_by=by.name, known_at=db.now_iso())
        )
        connection.execute(
            audit.insert().values(
                session_id=None,
                at=db.now_iso(),
                author=by.name,
                action="approve",
                reason=f"questionnaire definition {row.questionnaire_id} {row.version} ({sha})"[:1000],
            )
        )
