"""A questionnaire as a captured definition: a canonical JSON document, content-addressed.

A session stores the exact instrument it ran (every text, the patient's and the spoken wording,
options, points, codes, band sets, the band set in use, timing, version and file digest) so that
what describes it later never depends on the questionnaire file current at that time.
:func:`canonical` gives the plain-JSON form, :func:`questionnaire_from` rebuilds an equal
:class:`~kiosk.core.questionnaire.Questionnaire` (``questionnaire_from(canonical(q)) == q``), and
:func:`digest` is the SHA-256 of :func:`canonical_json`, the key it is stored under once.

Canonical JSON: keys sorted, no whitespace, UTF-8 (not ASCII-escaped), lists keep their order;
language maps are rebuilt in the order of ``languages``, so the rebuilt object iterates its texts
as the kiosk did. Pure data, no I/O.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import asdict
from typing import Any

from basis.errors import KioskError
from kiosk.core.questionnaire import (
    CONCERNS,
    PATIENT,
    Band,
    BandSet,
    Code,
    Entry,
    Formula,
    Item,
    Option,
    PracticeQuestion,
    Questionnaire,
    Subscale,
    Timing,
    Translation,
)

__all__ = ["FORMAT", "DefinitionError", "canonical", "canonical_json", "digest", "questionnaire_from"]

#: the version of this document's shape (a future shape would be read by a future kiosk)
FORMAT = 1


class DefinitionError(KioskError, ValueError):
    """A captured definition that does not rebuild a questionnaire (message says where and what)."""


def _code(code: Code | None) -> dict[str, str] | None:
    """A code as captured; its code system's display only where it has one (a definition
    captured before displays existed keeps its digest)."""
    if code is None:
        return None
    return {"system": code.system, "code": code.code} | ({"display": code.display} if code.display else {})


def _option(o: Option) -> dict[str, Any]:
    return {
        "number": o.number,
        "label": dict(o.label),
        "synonyms": {k: list(v) for k, v in o.synonyms.items()},
        "points": o.points,
        "patient": dict(o.patient),
        "code": _code(o.code),
    }


def _item(i: Item) -> dict[str, Any]:
    """An item as captured; format v2's parts only where they differ from v1's meaning (a v1
    instrument's definition, and so its digest, is what it was)."""
    extra: dict[str, Any] = {}
    if i.answered_by != PATIENT:
        extra["answered_by"] = i.answered_by
    if i.entry is not None:
        extra["input"] = asdict(i.entry)
    if i.instead_of:
        extra["instead_of"] = list(i.instead_of)
    return {
        "id": i.id,
        "number": i.number,
        "text": dict(i.text),
        "spoken": dict(i.spoken),
        "patient": dict(i.patient),
        "code": _code(i.code),
        "options": [_option(o) for o in i.options],
    } | extra


def _v2(q: Questionnaire) -> dict[str, Any]:
    """The instrument-level parts of format v2 that ``q`` uses (none for a v1 instrument)."""
    extra: dict[str, Any] = {}
    if q.reference:
        extra["source"] = q.reference
    if q.patient_title:
        extra["patient_title"] = dict(q.patient_title)
    if q.translations:
        extra["translations"] = {lang: asdict(t) for lang, t in q.translations.items()}
    if q.formula is not None:
        extra["formula"] = asdict(q.formula)
    if q.answered_by != PATIENT:
        extra["answered_by"] = q.answered_by
    if q.subscales:
        extra["subscales"] = [
            {"id": s.id, "label": dict(s.label), "items": list(s.items), "code": _code(s.code)} for s in q.subscales
        ]
    return extra


def _band(b: Band) -> dict[str, Any]:
    """A band as captured; ``concern`` only when declared (a definition captured before it
    existed keeps its digest)."""
    band: dict[str, Any] = {"id": b.id, "min": b.min, "max": b.max, "label": dict(b.label)}
    if b.concern is not None:
        band["concern"] = b.concern
    return band


def canonical(q: Questionnaire) -> dict[str, Any]:
    """Everything ``q`` says, as plain JSON values (``source``, a file path, is not part of it;
    ``reference``, the published source, is, as ``source``)."""
    return _v2(q) | {
        "format": FORMAT,
        "id": q.id,
        "version": q.version,
        "digest": q.digest,
        "title": dict(q.title),
        "languages": list(q.languages),
        "items": [_item(i) for i in q.items],
        "band_sets": [
            {
                "id": s.id,
                "source": s.source,
                "bands": [_band(b) for b in s.bands],
            }
            for s in q.band_sets.values()
        ],
        "band_set": q.band_set,
        "messages": {name: dict(texts) for name, texts in q.messages.items()},
        "familiarisation": [
            {
                "id": p.id,
                "checks": p.checks,
                "text": dict(p.text),
                "spoken": dict(p.spoken),
                "expected": p.expected,
                "options": [_option(o) for o in p.options],
            }
            for p in q.familiarisation
        ],
        "timing": asdict(q.timing),
        "code": _code(q.code),
        "total_code": _code(q.total_code),
    }


def canonical_json(definition: Mapping[str, Any]) -> str:
    """The one text of a definition that its digest is taken of."""
    return json.dumps(definition, sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False)


def digest(definition: Mapping[str, Any]) -> str:
    """SHA-256 (hex) of :func:`canonical_json`: the definition's content address."""
    return hashlib.sha256(canonical_json(definition).encode("utf-8")).hexdigest()


def questionnaire_from(definition: Mapping[str, Any], source: str = "") -> Questionnaire:
    """The questionnaire a captured definition describes (DefinitionError naming the part that
    does not fit). ``source`` names where it came from in messages (default: its digest)."""
    try:
        return _build(definition, source or f"captured definition {digest(definition)[:12]}")
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        if isinstance(exc, DefinitionError):
            raise
        raise DefinitionError(
            f"the captured definition does not describe a questionnaire ({type(exc).__name__}: {exc})"
        ) from None


def _concern(value: Any) -> str | None:
    if value is None or value in CONCERNS:
        return value
    raise DefinitionError(f"a band's concern must be one of {', '.join(CONCERNS)}, got {value!r:.40}")


def _build(d: Mapping[str, Any], source: str) -> Questionnaire:
    if d.get("format") != FORMAT:
        raise DefinitionError(f"captured definition of format {d.get('format')!r}; this kiosk reads format {FORMAT}")
    languages = tuple(d["languages"])
    if not languages or not all(isinstance(lang, str) for lang in languages):
        raise DefinitionError("the captured definition names no languages")

    def texts(value: Mapping[str, Any]) -> dict[str, str]:
        if not isinstance(value, Mapping) or not all(isinstance(v, str) for v in value.values()):
            raise DefinitionError(f"texts must map languages to text, got {value!r:.80}")
        order = [lang for lang in languages if lang in value] + [lang for lang in value if lang not in languages]
        return {lang: value[lang] for lang in order}

    def code(value: Mapping[str, str] | None) -> Code | None:
        return Code(str(value["system"]), str(value["code"]), str(value.get("display", ""))) if value else None

    def options(values: list[Mapping[str, Any]]) -> tuple[Option, ...]:
        built = tuple(
            Option(
                number=int(v["number"]),
                label=texts(v["label"]),
                synonyms={lang: tuple(words) for lang, words in texts_of_lists(v["synonyms"]).items()},
                points=v["points"],
                patient=texts(v["patient"]),
                code=code(v["code"]),
            )
            for v in values
        )
        if [o.number for o in built] != list(range(1, len(built) + 1)):
            raise DefinitionError("options must be numbered 1, 2, 3... in order")
        return built

    def texts_of_lists(value: Mapping[str, Any]) -> dict[str, list[str]]:
        order = [lang for lang in languages if lang in value] + [lang for lang in value if lang not in languages]
        return {lang: list(value[lang]) for lang in order}

    items = tuple(
        Item(
            id=str(v["id"]),
            number=int(v["number"]),
            text=texts(v["text"]),
            spoken=texts(v["spoken"]),
            options=options(v["options"]),
            code=code(v["code"]),
            patient=texts(v["patient"]),
            answered_by=str(v.get("answered_by", PATIENT)),
            entry=Entry(**v["input"]) if v.get("input") else None,
            instead_of=tuple(str(i) for i in v.get("instead_of", ())),
        )
        for v in d["items"]
    )
    if not items or any(
        (not item.options and item.entry is None) or any(o.points is None for o in item.options) for item in items
    ):
        raise DefinitionError("every item of a captured definition needs scored options or an input")
    band_sets = {
        str(s["id"]): BandSet(
            id=str(s["id"]),
            source=str(s["source"]),
            bands=tuple(
                Band(
                    id=str(b["id"]),
                    min=int(b["min"]),
                    max=int(b["max"]),
                    label=texts(b["label"]),
                    concern=_concern(b.get("concern")),
                )
                for b in s["bands"]
            ),
        )
        for s in d["band_sets"]
    }
    if d["band_set"] not in band_sets:
        raise DefinitionError(f"the band set in use, {d['band_set']!r}, is not one of the captured band sets")
    practice = tuple(
        PracticeQuestion(
            id=str(v["id"]),
            checks=str(v["checks"]),
            text=texts(v["text"]),
            spoken=texts(v["spoken"]),
            options=options(v["options"]),
            expected=int(v["expected"]),
        )
        for v in d["familiarisation"]
    )
    return Questionnaire(
        id=str(d["id"]),
        version=str(d["version"]),
        title=texts(d["title"]),
        patient_title=texts(d.get("patient_title", {})),
        languages=languages,
        items=items,
        band_sets=band_sets,
        band_set=str(d["band_set"]),
        messages={str(name): texts(value) for name, value in d["messages"].items()},
        familiarisation=practice,
        timing=Timing(**{k: float(v) for k, v in d["timing"].items()}),
        code=code(d["code"]),
        total_code=code(d["total_code"]),
        source=source,
        digest=str(d["digest"]),
        reference=str(d.get("source", "")),
        translations={
            str(lang): Translation(str(t["source"]), bool(t["validated"]))
            for lang, t in d.get("translations", {}).items()
        },
        formula=Formula(**d["formula"]) if d.get("formula") else None,
        subscales=tuple(
            Subscale(id=str(s["id"]), label=texts(s["label"]), items=tuple(s["items"]), code=code(s["code"]))
            for s in d.get("subscales", [])
        ),
        answered_by=str(d.get("answered_by", PATIENT)),
    )
