"""The site's batteries, as its station is configured (``kiosk station --battery "CGA=barthel,
lawton,gds15"``, repeatable): each a name and its instruments in the order the patient does them,
the order the kiosks' ``instruments:`` give (issue 36: the order form ran a battery in the order
its boxes happened to be listed, and could not offer the site's battery).

The order form offers each battery by name, lists the instruments in the site's order (every
battery's, first seen first, then the others), and an order keeps that order, never the order of
a list or the alphabet.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from basis import record

#: a battery's name as staff read it in the form: letters, digits, spaces and - _ . ( ), 1 to 40
NAME = re.compile(r"[\w][\w .()-]{0,39}")
#: an instrument's id as the kiosks and the station name it
INSTRUMENT = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")


@record
class Battery:
    name: str
    instruments: tuple[str, ...]


def parse(text: str) -> Battery:
    """``NAME=ID,ID,...`` as given on the command line; ValueError with one sentence naming the
    problem (the option's name is the caller's)."""
    name, sep, ids = text.partition("=")
    name = name.strip()
    if not sep or not NAME.fullmatch(name):
        raise ValueError(f"{text[:60]!r}: give NAME=ID,ID,... with a name of 1 to 40 letters, digits or spaces")
    instruments = tuple(i.strip() for i in ids.split(","))
    bad = [i for i in instruments if not INSTRUMENT.fullmatch(i)]
    if bad:  # "CGA=" and "CGA=a,,b" name an empty id
        raise ValueError(f"battery {name}: {bad[0][:40]!r} is not an instrument id")
    if len(set(instruments)) != len(instruments):
        raise ValueError(f"battery {name}: an instrument is named twice")
    return Battery(name, instruments)


def parse_all(texts: Sequence[str]) -> tuple[Battery, ...]:
    """Every ``--battery`` option; two with one name are one mistake."""
    found = tuple(parse(t) for t in texts)
    names = [b.name for b in found]
    if len(set(names)) != len(names):
        raise ValueError(f"battery {next(n for n in names if names.count(n) > 1)} is given twice")
    return found


def site_order(offered: Sequence[str], batteries: Sequence[Battery]) -> list[str]:
    """``offered`` instrument ids in the site's order: each battery's, first seen first, then the rest
    as they came."""
    configured = list(dict.fromkeys(i for b in batteries for i in b.instruments if i in offered))
    return configured + [i for i in offered if i not in configured]


def chosen(battery: str, ticked: Sequence[str], offered: Sequence[str], batteries: Sequence[Battery]) -> list[str]:
    """The instruments of an order: the named ``battery``'s in its order (an unknown name:
    ValueError), then the ``ticked`` ones it lacks, in the site's order (:func:`site_order`).
    Ids the station does not offer are kept (the order then says which is unknown)."""
    first: tuple[str, ...] = ()
    if battery:
        found = next((b for b in batteries if b.name == battery), None)
        if found is None:
            raise ValueError(f"battery {battery[:40]!r} is not one of this site's")
        first = found.instruments
    rank = {i: n for n, i in enumerate(site_order(offered, batteries))}
    rest = sorted((i for i in dict.fromkeys(ticked) if i and i not in first), key=lambda i: rank.get(i, len(rank)))
    return [*first, *rest]
