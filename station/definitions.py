"""The questionnaire definitions sessions ran, read once per content: a definition is stored once
per SHA-256 (``definitions``) and never changes under its hash, so this process keeps the parsed
body and the questionnaire it rebuilds by hash, and a page listing a hundred results of one
instrument parses its 15-35 KB definition once, not once per row.
"""

from __future__ import annotations

import json
import threading
from collections import OrderedDict
from collections.abc import Iterable, Mapping
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection

from kiosk.core.questionnaire import Questionnaire
from kiosk.core.questionnaire.definition import DefinitionError, questionnaire_from
from kiosk.export import ExportError
from kiosk.store.records import StoredSession
from station.db import definitions
from station.formulas import guarded
from station.known import known

#: definitions kept parsed in this process (a site runs a handful)
KEPT = 128


class _Parsed:
    """A definition's body and the questionnaire it describes (or why it describes none)."""

    __slots__ = ("body", "guarded", "problem", "questionnaire", "sha")

    def __init__(self, body: Mapping[str, Any], sha: str = "") -> None:
        self.body, self.sha = body, sha
        self.questionnaire: Questionnaire | None = None
        self.problem = ""
        #: the questionnaire as the station scores it, unknown (False) and known (True)
        self.guarded: dict[bool, Questionnaire] = {}
        try:
            self.questionnaire = questionnaire_from(body)
        except DefinitionError as exc:
            self.problem = str(exc)

    def scored(self, is_known: bool) -> Questionnaire | None:
        """The questionnaire whose formula runs only in the formula process, and only if known."""
        if self.questionnaire is None:
            return None
        if is_known not in self.guarded:
            self.guarded[is_known] = guarded(self.questionnaire, self.sha, self.body, is_known)
        return self.guarded[is_known]


_kept: OrderedDict[str, _Parsed] = OrderedDict()
_lock = threading.Lock()
#: the definitions this station knows, as far as this process has read (a definition, once
#: known, stays known: station.known)
_known: set[str] = set()


def _keep(sha: str, parsed: _Parsed) -> _Parsed:
    with _lock:
        _kept[sha] = parsed
        _kept.move_to_end(sha)
        while len(_kept) > KEPT:
            _kept.popitem(last=False)
    return parsed


def parsed(connection: Connection, shas: Iterable[str]) -> dict[str, _Parsed]:
    """The parsed definitions of ``shas`` (those stored), reading only the ones not kept yet, in
    one query, and which of them the station knows (another)."""
    wanted = {s for s in shas if s}
    unknown = wanted - _known
    if unknown:
        _known.update(known(connection, unknown))
    with _lock:
        found = {s: _kept[s] for s in wanted if s in _kept}
    missing = wanted - found.keys()
    if missing:
        rows = connection.execute(
            sa.select(definitions.c.sha256, definitions.c.body).where(definitions.c.sha256.in_(sorted(missing)))
        )
        for sha, body in rows:
            found[sha] = _keep(sha, _Parsed(json.loads(body), sha))
    return found


def body_of(connection: Connection, sha: str) -> Mapping[str, Any] | None:
    found = parsed(connection, [sha]).get(sha)
    return found.body if found else None


def questionnaire_for(stored: StoredSession, fallback: Questionnaire | None = None) -> Questionnaire:
    """The questionnaire ``stored`` ran, from its captured definition (parsed once per hash in
    this process); without one ``fallback``; ExportError if neither (as
    :func:`kiosk.export.captured.questionnaire_of`)."""
    if stored.definition is None:
        if fallback is None:
            raise ExportError(f"session {stored.id} has no captured questionnaire definition")
        return fallback
    with _lock:
        kept = _kept.get(stored.definition_sha256)
    if kept is None or kept.body is not stored.definition:
        # a definition this module did not read: parsed here, and known only if read as known
        kept = _Parsed(stored.definition, stored.definition_sha256)
    scored = kept.scored(stored.definition_sha256 in _known)
    if scored is None:
        raise ExportError(f"session {stored.id}: {kept.problem}")
    return scored
