"""Is a staff input's ``unit`` a UCUM code? A check of the UCUM grammar over a small table of units.

The unit is exported as the item's ``questionnaire-unit`` Coding in the UCUM system, so
``kilos`` there is a wrong code, not a spelling. UCUM (https://ucum.org/ucum, "The Unified Code
for Units of Measure", Regenstrief) writes a unit as a term: components joined by ``.``
(times) and ``/`` (divided by), a leading ``/`` allowed, each component a unit atom with an
optional prefix (metric atoms only) and an integer exponent (``m2``), a parenthesised term, a
number (``10*3``) or an annotation in braces (``{score}``), which an atom may also carry
(``kg{dry}``). The atoms here are those a geriatric assessment measures with (mass, length,
time, volume, pressure, temperature, counts), not UCUM's whole table: an exotic unit is
refused, with the code to write instead where a common mistake is known.
"""

from __future__ import annotations

import difflib
import re

__all__ = ["unit_problem"]

#: UCUM's metric prefixes (they go only on metric atoms)
PREFIXES = ("da", "Y", "Z", "E", "P", "T", "G", "M", "k", "h", "d", "c", "m", "u", "n", "p", "f", "a", "z", "y")
#: metric atoms: gram, metre, second, litre (l and L), mole, kelvin, degree Celsius, pascal,
#: hertz, newton, joule, watt, equivalents, international units, bar, calorie
METRIC = frozenset(
    {"g", "m", "s", "l", "L", "mol", "K", "Cel", "Pa", "Hz", "N", "J", "W", "eq", "U", "[iU]", "[IU]", "bar", "cal"}
    | {"m[Hg]", "m[H2O]"}
)
#: non-metric atoms: minute, hour, day, week, month, year, percent, inch, foot, pound, ounce,
#: degree Fahrenheit, beats and breaths need annotations ({beats}/min)
OTHER = frozenset({"min", "h", "d", "wk", "mo", "a", "%", "[in_i]", "[ft_i]", "[lb_av]", "[oz_av]", "[degF]", "[pH]"})
#: what people write for a unit, and its UCUM code
SAY_INSTEAD = {
    "kilo": "kg",
    "kilos": "kg",
    "kilogram": "kg",
    "kilograms": "kg",
    "kgs": "kg",
    "grams": "g",
    "gram": "g",
    "centimetre": "cm",
    "centimetres": "cm",
    "centimeter": "cm",
    "centimeters": "cm",
    "metre": "m",
    "metres": "m",
    "meter": "m",
    "meters": "m",
    "seconds": "s",
    "second": "s",
    "sec": "s",
    "secs": "s",
    "minutes": "min",
    "minute": "min",
    "mins": "min",
    "hours": "h",
    "hour": "h",
    "hrs": "h",
    "hr": "h",
    "days": "d",
    "day": "d",
    "weeks": "wk",
    "week": "wk",
    "months": "mo",
    "month": "mo",
    "years": "a",
    "year": "a",
    "yrs": "a",
    "yr": "a",
    "y": "a",
    "litre": "L",
    "litres": "L",
    "liter": "L",
    "liters": "L",
    "mmhg": "mm[Hg]",
    "mmHg": "mm[Hg]",
    "bpm": "{beats}/min",
    "percent": "%",
    "lb": "[lb_av]",
    "lbs": "[lb_av]",
    "pounds": "[lb_av]",
    "inch": "[in_i]",
    "inches": "[in_i]",
    "in": "[in_i]",
    "kg/m²": "kg/m2",
    "°C": "Cel",
    "C": "Cel",
    "points": "{score}",
    "µg": "ug",
    "μg": "ug",
    "score": "{score}",
}
#: the units a clinician most often means, for a "did you mean"
COMMON = ("kg", "g", "cm", "m", "mm", "s", "min", "h", "d", "wk", "mo", "a", "%", "L", "mL", "kg/m2", "mm[Hg]")

_ANNOTATION = r"\{[!-z|~]*\}"  # printable ASCII but braces, as UCUM says
_TOKEN = re.compile(
    rf"(?P<annotation>{_ANNOTATION})|(?P<op>[./()])|(?P<number>10[*^][+-]?\d+|\d+)|(?P<atom>[^./(){{}}]+)"
)
_EXPONENT = re.compile(r"^(?P<unit>.*?)(?P<exponent>[+-]?\d+)?$")


def _atom(text: str) -> bool:
    """Whether ``text`` is a unit atom here, with its prefix and exponent (``cm2``, ``mm[Hg]``)."""
    match = _EXPONENT.match(text)
    unit = match.group("unit") if match else text
    if unit in OTHER or unit in METRIC:
        return True
    return any(unit.startswith(p) and unit[len(p) :] in METRIC for p in PREFIXES)


def unit_problem(unit: str) -> str | None:
    """Why ``unit`` is not a UCUM code (with the code to write, where known), or None."""
    if unit in SAY_INSTEAD:
        return f"{unit!r} is not a UCUM unit: write {SAY_INSTEAD[unit]!r}"
    if len(unit) > 40 or not unit.isascii() or " " in unit:
        return f"{unit!r} is not a UCUM unit (UCUM codes are short, in ASCII, without spaces: kg, cm, a, kg/m2)"
    position, depth, expecting_term = 0, 0, True
    for match in _TOKEN.finditer(unit):
        if match.start() != position:
            break
        position = match.end()
        kind, text = match.lastgroup, match.group()
        if kind == "op" and text in "./":
            if expecting_term and not (text == "/" and match.start() == 0):
                return _bad(unit, f"{text!r} needs a unit on each side")
            expecting_term = True
        elif kind == "op":
            depth += 1 if text == "(" else -1
            if depth < 0 or (text == ")" and expecting_term):
                return _bad(unit, "its parentheses do not pair")
            expecting_term = text == "("
        elif kind == "atom" and not _atom(text.split("{")[0]):
            return _bad(unit, f"{text!r} is not a unit the kiosk knows")
        else:
            expecting_term = False
    if position != len(unit) or depth or expecting_term:
        return _bad(unit, "it does not follow UCUM's grammar")
    return None


def _bad(unit: str, why: str) -> str:
    same = [c for c in COMMON if c.lower() == unit.lower()]
    close = same or difflib.get_close_matches(unit, COMMON, n=1, cutoff=0.5)
    hint = f" (did you mean {close[0]!r}?)" if close else " (e.g. kg, cm, s, min, a for years, kg/m2, {score})"
    return f"{unit!r} is not a UCUM unit: {why}{hint}"
