"""Instruments written in format v2, as a clinician would write them, for the model and export tests.

Each is a whole YAML file (text), so positions in problems can be checked against it. They are
not the shipped instruments: they exercise the features (shared scores, yes/no both ways, negative
points, staff items, a formula total, six options, subscales) the way any faithful instrument may.
"""

from __future__ import annotations

from pathlib import Path

from kiosk.core.questionnaire import Questionnaire, load_questionnaire

HEAD = """\
id: {id}
version: "1"
source: "A test instrument (no publication)"
title: {{en: {title}, es: {title}}}
languages: [en, es]
total_code: {{system: "urn:test:total", code: "{id}", display: "{title} total"}}
timing: {{attempt_window_s: 20}}
"""


def texts(words: str) -> str:
    return f'{{en: "{words}", es: "{words} (es)"}}'


def choice(item_id: str, points: list[int], *, staff: bool = False, code: bool = False) -> str:
    """An item with one option per points value (labels 'item N')."""
    lines = [f"  - id: {item_id}"]
    if staff:
        lines.append("    answered_by: staff")
    lines += [f"    text: {texts(item_id + '?')}"]
    if not staff:
        lines.append(f"    spoken: {texts('Say ' + item_id)}")
    lines.append("    options:")
    for n, p in enumerate(points, start=1):
        lines.append(f"      - points: {p}")
        lines.append(f"        label: {texts(f'{item_id} {n}')}")
        if code:
            lines.append(f'        code: {{system: "urn:test:{item_id}", code: "c{n}", display: "{item_id} {n}"}}')
    return "\n".join(lines) + "\n"


def yes_no(item_id: str, yes: int, no: int) -> str:
    return (
        f"  - id: {item_id}\n    text: {texts(item_id + '?')}\n    spoken: {texts('Say ' + item_id)}\n"
        f'    answers: yes_no\n    points: {{"yes": {yes}, "no": {no}}}\n'
    )


def staff_input(item_id: str, kind: str, low: float, high: float, unit: str) -> str:
    return (
        f"  - id: {item_id}\n    answered_by: staff\n    text: {texts(item_id + '?')}\n"
        f"    input: {{type: {kind}, min: {low}, max: {high}, unit: {unit}}}\n"
    )


def bands(*ranges: tuple[str, int, int]) -> str:
    lines = ["bands:", "  default: main", "  sets:", "    main:", "      source: test cut-offs", "      ranges:"]
    for band_id, low, high in ranges:
        lines.append(f"        - {{id: {band_id}, min: {low}, max: {high}, label: {texts(band_id)}}}")
    return "\n".join(lines) + "\n"


def instrument(instrument_id: str, items: str, band_text: str, extra: str = "") -> str:
    return HEAD.format(id=instrument_id, title=instrument_id.upper()) + extra + band_text + "items:\n" + items


#: Lawton-like: 0/1 points shared by several levels; housekeeping with 5 levels
LAWTON = instrument(
    "lawtonish",
    choice("telephone", [1, 1, 1, 0]) + choice("housekeeping", [1, 1, 1, 1, 0]) + choice("laundry", [1, 1, 0]),
    bands(("low", 0, 1), ("high", 2, 3)),
)

#: GDS-like: yes/no scored either way (No scores on the reverse-scored item 1)
GDS = instrument(
    "gdsish",
    yes_no("satisfied", 0, 1) + yes_no("bored", 1, 0) + yes_no("helpless", 1, 0),
    bands(("normal", 0, 1), ("depressed", 2, 3)),
    "translations:\n  en: {source: test original, validated: true}\n  es: {source: our own, validated: false}\n",
)

#: a negative-points item, a six-option item and subscales
MIXED = instrument(
    "mixed",
    choice("pain", [-2, 0, 3], code=True)
    + choice("steps", [0, 1, 2, 3, 4, 5])
    + choice("sleep", [0, 2])
    + choice("appetite", [0, 2]),
    bands(("poor", -2, 3), ("fair", 4, 8), ("good", 9, 12)),
    "scoring:\n  total: sum\n  subscales:\n"
    f"    - {{id: body, label: {texts('Body')}, items: [pain, steps], "
    'code: {system: "urn:test:sub", code: "body", display: "Body"}}\n'
    f"    - {{id: rest, label: {texts('Rest')}, items: [sleep, appetite]}}\n",
)

#: a staff-entered integer and a staff choice; the total is a formula: errors adjusted for education
FORMULA = (
    "%resource.item.where(linkId = 'recall' or linkId = 'orientation' or linkId = 'judged').answer.value"
    ".weight().sum() + iif(%resource.item.where(linkId = 'education').answer.value < 9, -1, 0)"
)
STAFFED = instrument(
    "staffed",
    choice("recall", [0, 1, 2], code=True)
    + choice("orientation", [0, 1, 2])
    + staff_input("education", "integer", 0, 30, "a")
    + choice("judged", [0, 1], staff=True),
    bands(("intact", -1, 1), ("impaired", 2, 5)),
    f'scoring:\n  total:\n    fhirpath: "{FORMULA}"\n    min: -1\n    max: 5\n',
)

#: MNA-SF-like: staff measure weight and height (decimals); the formula turns the BMI into points
HEIGHT_M = "(%resource.item.where(linkId = 'height').answer.value / 100)"
BMI = f"(%resource.item.where(linkId = 'weight').answer.value / ({HEIGHT_M} * {HEIGHT_M}))"
BMI_FORMULA = (
    "%resource.item.where(linkId = 'intake').answer.value.weight().sum() + "
    f"iif({BMI} < 19, 0, iif({BMI} < 21, 1, iif({BMI} < 23, 2, 3)))"
)
MEASURED = instrument(
    "measured",
    choice("intake", [0, 1, 2])
    + staff_input("weight", "decimal", 20, 250, "kg")
    + staff_input("height", "decimal", 100, 220, "cm"),
    bands(("malnourished", 0, 1), ("at_risk", 2, 3), ("normal", 4, 5)),
    f'scoring:\n  total:\n    fhirpath: "{BMI_FORMULA}"\n    min: 0\n    max: 5\n',
)


def write(tmp_path: Path, text: str, name: str = "instrument.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def load(tmp_path: Path, text: str, name: str = "instrument.yaml") -> Questionnaire:
    return load_questionnaire(write(tmp_path, text, name))


#: MNA-SF-like: the calf circumference is measured instead of the weight and height of the BMI
#: when the patient cannot be weighed (bed-bound): either side completes the result
CALF = "%resource.item.where(linkId = 'calf').answer.value"
STAND_IN_FORMULA = (
    "%resource.item.where(linkId = 'intake').answer.value.weight().sum() + "
    f"iif({CALF}.exists(), iif({CALF} < 31, 0, 3), "
    f"iif({BMI} < 19, 0, iif({BMI} < 21, 1, iif({BMI} < 23, 2, 3))))"
)
STOOD_IN = instrument(
    "standin",
    choice("intake", [0, 1, 2])
    + staff_input("weight", "decimal", 20, 250, "kg")
    + staff_input("height", "decimal", 100, 220, "cm")
    + staff_input("calf", "decimal", 10, 60, "cm")
    + "    instead_of: [weight, height]\n",
    bands(("malnourished", 0, 1), ("at_risk", 2, 3), ("normal", 4, 5)),
    f'scoring:\n  total:\n    fhirpath: "{STAND_IN_FORMULA}"\n    min: 0\n    max: 5\n',
)
