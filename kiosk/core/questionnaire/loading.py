"""Loading a questionnaire file: parse with positions, check everything, build the model.

Nothing is half-loaded: a file with any problem raises :class:`QuestionnaireError` listing all of
them, because clinicians edit the YAML by hand and should fix every mistake in one pass.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from functools import cache
from pathlib import Path
from typing import Any

from basis.errors import KioskError
from fileio.positions import Problem, parse, parse_file
from kiosk.core.questionnaire.checks import check
from kiosk.core.questionnaire.model import (
    Item,
    PracticeQuestion,
    Questionnaire,
    Timing,
    Translation,
)
from kiosk.core.questionnaire.parts import PATIENT, Band, BandSet, Code, Entry, Option
from kiosk.core.questionnaire.scoring import Formula, Subscale
from kiosk.core.words import load_words

#: the LOINC answers of a yes/no item (``answers: yes_no``): Yes is option 1, No option 2
YES = Code("http://loinc.org", "LA33-6", "Yes")
NO = Code("http://loinc.org", "LA32-8", "No")

#: where the bundled questionnaires and their schema live (the package is installed as files,
#: never zipped)
_INSTRUMENTS = Path(__file__).parent / "instruments"
DEFAULT_FILE = "barthel.yaml"
SCHEMA_FILE = "questionnaire.schema.json"


class QuestionnaireError(KioskError, ValueError):
    """A questionnaire file is unusable; ``problems`` lists every reason with its position."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = problems
        first = str(problems[0]) if problems else "invalid questionnaire"
        more = f" (and {len(problems) - 1} more problems)" if len(problems) > 1 else ""
        super().__init__(first + more)


# --------------------------------------------------------------------------------------------


def bundled_path(name: str = DEFAULT_FILE) -> Path:
    """Path of a file shipped in ``kiosk/core/questionnaire/instruments``."""
    return _INSTRUMENTS / name


@cache
def _schema() -> dict[str, Any]:
    return json.loads(bundled_path(SCHEMA_FILE).read_text(encoding="utf-8"))


def load_questionnaire(path: str | Path | None = None) -> Questionnaire:
    """Load and validate a questionnaire (default: the bundled Barthel file).

    Raises :class:`QuestionnaireError` listing every problem (an unreadable file is one problem).
    """
    file = Path(path) if path is not None else bundled_path()
    name = str(path if path is not None else file)
    data, problems = check(parse_file(file, name), name, _schema())
    if problems:
        raise QuestionnaireError(problems)
    return _build(data, str(file))


def check_questionnaire_file(path: str | Path) -> list[Problem]:
    """Every problem in a questionnaire file (empty if it is valid): the checks :func:`load_questionnaire`
    makes, so a file this accepts is one the kiosk runs. Unreadable: one problem."""
    return check_questionnaire(path)[1]


def check_questionnaire(path: str | Path) -> tuple[bool, list[Problem]]:
    """(readable, every problem) of a questionnaire file; ``readable`` is False when the file could
    not be read as YAML at all (then its one problem says why)."""
    parsed = parse_file(path)
    return parsed[1] is not None, check(parsed, str(path), _schema())[1]


def check_questionnaire_text(text: str, filename: str) -> tuple[Any, list[Problem]]:
    """Parse and check questionnaire YAML; returns (data, problems). Data is None on a syntax error."""
    return check(parse(text, filename), filename, _schema())


def _build(data: dict[str, Any], source: str) -> Questionnaire:
    def code(value: Mapping[str, str] | None) -> Code | None:
        return Code(value["system"], value["code"], value.get("display", "")) if value else None

    def opts(values: list[dict[str, Any]]) -> tuple[Option, ...]:
        return tuple(
            Option(
                number=i,
                label=dict(v["label"]),
                synonyms={lang: tuple(words) for lang, words in v.get("synonyms", {}).items()},
                points=v.get("points"),
                patient=dict(v.get("patient", {})),
                code=code(v.get("code")),
            )
            for i, v in enumerate(values, start=1)
        )

    languages = tuple(data["languages"])
    items = tuple(
        Item(
            id=v["id"],
            number=n,
            text=dict(v["text"]),
            spoken=dict(v.get("spoken", {})),
            options=yes_no(v["points"], languages) if v.get("answers") == "yes_no" else opts(v.get("options", [])),
            code=code(v.get("code")),
            patient=dict(v.get("patient", {})),
            answered_by=v.get("answered_by", PATIENT),
            entry=Entry(**v["input"]) if "input" in v else None,
            instead_of=tuple(v.get("instead_of", ())),
        )
        for n, v in enumerate(data["items"], start=1)
    )
    scoring = data.get("scoring", {})
    total = scoring.get("total", "sum")
    formula = Formula(total["fhirpath"], total["min"], total["max"]) if isinstance(total, dict) else None
    subscales = tuple(
        Subscale(
            id=v["id"],
            label=dict(v["label"]),
            items=tuple(i.id for i in items if i.id in v["items"]),
            code=code(v.get("code")),
        )
        for v in scoring.get("subscales", [])
    )
    practice = tuple(
        PracticeQuestion(
            id=v["id"],
            checks=v["checks"],
            text=dict(v["text"]),
            spoken=dict(v["spoken"]),
            options=opts(v["options"]),
            expected=v["expected"],
        )
        for v in data.get("familiarisation", [])
    )
    band_sets = {
        name: BandSet(
            id=name,
            source=v.get("source", ""),
            bands=tuple(
                Band(id=b["id"], min=b["min"], max=b["max"], label=dict(b["label"]), concern=b.get("concern"))
                for b in sorted(v["ranges"], key=lambda b: b["min"])
            ),
        )
        for name, v in data["bands"]["sets"].items()
    }
    return Questionnaire(
        id=data["id"],
        version=str(data.get("version", "")),
        title=dict(data["title"]),
        patient_title=dict(data.get("patient_title") or {}),
        languages=languages,
        items=items,
        band_sets=band_sets,
        band_set=data["bands"]["default"],
        messages={k: dict(v) for k, v in data.get("messages", {}).items()},
        familiarisation=practice,
        timing=Timing().with_overrides(data.get("timing")),
        code=code(data.get("code")),
        total_code=code(data.get("total_code")),
        source=source,
        digest=hashlib.sha256(json.dumps(data, sort_keys=True, ensure_ascii=False).encode()).hexdigest(),
        reference=data.get("source", ""),
        translations={
            lang: Translation(v["source"], v["validated"]) for lang, v in data.get("translations", {}).items()
        },
        formula=formula,
        subscales=subscales,
        answered_by=data.get("answered_by", PATIENT),
    )


def yes_no(points: Mapping[str, int], languages: tuple[str, ...]) -> tuple[Option, ...]:
    """The two options of a yes/no item: Yes (1) and No (2), worded from the kiosk's words files
    (``answers``) in each of ``languages``, coded LOINC LA33-6 / LA32-8, scored by ``points``."""
    words = load_words()

    def option(number: int, name: str, code: Code) -> Option:
        return Option(
            number=number,
            label={lang: words[lang].answers[f"{name}_label"] for lang in languages},
            synonyms={lang: tuple(words[lang].answers[f"{name}_words"]) for lang in languages},
            points=points[name],
            patient={lang: words[lang].answers[f"{name}_patient"] for lang in languages},
            code=code,
        )

    return option(1, "yes", YES), option(2, "no", NO)
