"""A stored session described as it was recorded: its captured questionnaire and identity.

Every caller that describes a stored session (``kiosk results``, the clinician's screens, the ward
station's pages and exports) asks here for the :class:`~kiosk.core.questionnaire.Questionnaire` and the
:class:`~kiosk.export.ExportSite` of that session, rebuilt from what the session captured
(:mod:`kiosk.core.questionnaire.definition`), never from today's questionnaire file or configuration. The exports of
several sessions are made per group of sessions sharing a definition and an identity, then put
together, so that each result names its own questionnaire version and its own site and kiosk.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence
from functools import lru_cache
from typing import Any

from kiosk.core.questionnaire import Questionnaire, pending_words, result_words
from kiosk.core.questionnaire.definition import DefinitionError, canonical_json, questionnaire_from
from kiosk.core.review import Review
from kiosk.core.site import ExportSite, default_kiosk_id, site_from_identity
from kiosk.export.result import ExportError, rescore
from kiosk.store.records import StoredSession

__all__ = ["bundle_of", "csv_of", "questionnaire_of", "result_line", "site_of", "wide_csv_of", "wide_csv_tables"]


def result_line(stored: StoredSession) -> str:
    """A stored session's result in one short line of a list ("Total 85 of 100; Mild
    dependence", "No total yet: waiting for staff: Weight (kg)", "No total: 2 of 10 questions
    not answered"), or why it cannot be scored: what the clinician's list and ``kiosk results``
    show beside each session (the detail names every missing item)."""
    try:
        q = questionnaire_of(stored)
        score = rescore(q, stored)
    except ExportError as error:
        return f"cannot be scored: {error}"
    patient = [i for i in score.missing if i not in score.awaiting_staff]
    if patient and not score.problem:
        staff = pending_words(q, score).split("; ")[-1] if score.awaiting_staff else ""
        return f"No total: {len(patient)} of {len(q.items)} questions not answered" + (f"; {staff}" if staff else "")
    return result_words(q, score)


@lru_cache(maxsize=64)
def _rebuilt(text: str) -> Questionnaire:
    return questionnaire_from(json.loads(text))


def questionnaire_of(stored: StoredSession, fallback: Questionnaire | None = None) -> Questionnaire:
    """The questionnaire ``stored`` ran, from its captured definition (rebuilt once per content).
    Without one (a source that never captured it) ``fallback``; ExportError if neither."""
    if stored.definition is None:
        if fallback is None:
            raise ExportError(f"session {stored.id} has no captured questionnaire definition")
        return fallback
    try:
        return _rebuilt(canonical_json(stored.definition))
    except DefinitionError as exc:
        raise ExportError(f"session {stored.id}: {exc}") from None


def site_of(stored: StoredSession, kiosk_id: str | None = None) -> ExportSite:
    """The identity ``stored`` was recorded under (site, kiosk, FHIR systems). Fields it lacks
    take their defaults, the kiosk id ``kiosk_id`` (the station: the kiosk that sent it)."""
    identity = dict(stored.identity)
    return site_from_identity(identity, identity.get("kiosk_id") or kiosk_id or default_kiosk_id())


def _groups(
    sessions: Sequence[StoredSession], reviews: Sequence[Review | None] | None, kiosk_id: str | None
) -> list[tuple[Questionnaire, ExportSite, list[StoredSession], list[Review | None]]]:
    """Sessions grouped by (definition, identity), in order of first appearance."""
    if reviews is not None and len(reviews) != len(sessions):
        raise ExportError(f"{len(sessions)} sessions but {len(reviews)} reviews: give one review per session")
    groups: dict[tuple[str, tuple[tuple[str, Any], ...]], tuple[Questionnaire, ExportSite, list, list]] = {}
    for stored, review in zip(sessions, reviews or [None] * len(sessions)):
        site = site_of(stored, kiosk_id)
        key = (stored.definition_sha256 or stored.id, tuple(sorted(vars(site).items())))
        q = questionnaire_of(stored)
        group = groups.setdefault(key, (q, site, [], []))
        group[2].append(stored)
        group[3].append(review)
    return list(groups.values())


#: what an export of no session at all names: (the questionnaire, the site), e.g. the configuration's
Empty = tuple[Questionnaire, ExportSite]


def bundle_of(
    sessions: Sequence[StoredSession],
    reviews: Sequence[Review | None] | None = None,
    kiosk_id: str | None = None,
    *,
    empty: Empty | None = None,
) -> dict[str, Any]:
    """One FHIR transaction Bundle of ``sessions``, each described by its own definition and
    identity (:func:`kiosk.export.transaction_bundle` per group; an entry several groups share,
    such as the kiosk's Device, appears once)."""
    from kiosk.export.bundle import transaction_bundle  # FHIR loads when a bundle is asked for

    groups = _groups(sessions, reviews, kiosk_id)
    if not groups:
        q, site = _empty(empty, kiosk_id)
        return transaction_bundle(q, [], site=site)
    bundles = [transaction_bundle(q, group, _reviews(found), site=site) for q, site, group, found in groups]
    merged, seen, entries = dict(bundles[0]), set(), []
    for bundle in bundles:
        for entry in bundle.get("entry", []):
            key = (entry.get("fullUrl"), canonical_json(entry))
            if key not in seen:
                seen.add(key)
                entries.append(entry)
    if entries:
        merged["entry"] = entries
    return merged


def _reviews(found: list[Review | None]) -> list[Review] | None:
    return None if all(r is None for r in found) else [r or Review.unreviewed() for r in found]


def _empty(empty: Empty | None, kiosk_id: str | None) -> Empty:
    if empty is not None:
        return empty
    from kiosk.core.questionnaire import load_questionnaire

    return load_questionnaire(), ExportSite(kiosk_id=kiosk_id or "kiosk")


def _merge_csv(texts: list[str]) -> str:
    """CSV texts put together under one header (the union of their columns, in first-seen order)."""
    if len(texts) == 1:
        return texts[0]
    header: list[str] = []
    rows: list[dict[str, str]] = []
    for text in texts:
        reader = csv.DictReader(io.StringIO(text))
        header += [c for c in reader.fieldnames or () if c not in header]
        rows += list(reader)
    out = io.StringIO()
    writer = csv.DictWriter(out, header, lineterminator="\n", restval="")
    writer.writeheader()
    writer.writerows(rows)
    return out.getvalue()


def csv_of(
    sessions: Sequence[StoredSession],
    reviews: Sequence[Review | None] | None = None,
    kiosk_id: str | None = None,
    *,
    bom: bool = False,
    empty: Empty | None = None,
) -> str:
    """The long CSV (:func:`kiosk.export.csv_text`) of ``sessions``, each with its own definition
    and identity."""
    from kiosk.export.tables import csv_text

    groups = _groups(sessions, reviews, kiosk_id)
    if not groups:
        q, site = _empty(empty, kiosk_id)
        return csv_text(q, [], None, site, bom=bom)
    return ("\ufeff" if bom else "") + _merge_csv(
        [csv_text(q, group, _reviews(found), site) for q, site, group, found in groups]
    )


def wide_csv_tables(
    sessions: Sequence[StoredSession],
    reviews: Sequence[Review | None] | None = None,
    kiosk_id: str | None = None,
    *,
    bom: bool = False,
    empty: Empty | None = None,
) -> dict[str, str]:
    """The wide CSV (:func:`kiosk.export.wide_csv_text`) of ``sessions`` as one table per
    instrument, by questionnaire id in order of first appearance: one row per session under that
    instrument's own item columns (the versions of one instrument share a table, under the
    union of their columns). A researcher's table never mixes a Barthel row with a GDS row."""
    from kiosk.export.tables import wide_csv_text

    groups = _groups(sessions, reviews, kiosk_id)
    if not groups:
        q, site = _empty(empty, kiosk_id)
        return {q.id: wide_csv_text(q, [], None, site, bom=bom)}
    texts: dict[str, list[str]] = {}
    for q, site, group, found in groups:
        texts.setdefault(q.id, []).append(wide_csv_text(q, group, _reviews(found), site))
    return {qid: ("\ufeff" if bom else "") + _merge_csv(parts) for qid, parts in texts.items()}


def wide_csv_of(
    sessions: Sequence[StoredSession],
    reviews: Sequence[Review | None] | None = None,
    kiosk_id: str | None = None,
    *,
    bom: bool = False,
    empty: Empty | None = None,
) -> str:
    """The wide CSV of ``sessions`` of one instrument (:func:`wide_csv_tables`); ExportError naming
    the instruments when they ran several, which need a table each."""
    tables = wide_csv_tables(sessions, reviews, kiosk_id, bom=bom, empty=empty)
    if len(tables) > 1:
        raise ExportError(
            f"these sessions ran {len(tables)} instruments ({', '.join(tables)}): "
            "the wide CSV is one table per instrument"
        )
    return next(iter(tables.values()))
