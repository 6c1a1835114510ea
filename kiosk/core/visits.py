"""How a visit begins at the kiosk: an order from the ward station (confirmed by staff with the
order's code), staff typing a patient identifier on the clinician screen, or a walk-up where the
site allows it. Plain data and rules, no Textual, no network (the station side is
``kiosk.sync.orders``).

Every session says how it began in a ``visit`` entry of its log, written in the start's own
transaction (:attr:`kiosk.core.session.Session.visit`): ``order <id>``, ``staff`` or ``walk-up``. The
station files an ordered result under its order from that entry, and marks walk-ups as such.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from basis import record
from kiosk.core.answerers import Answerer, answerer

WALK_UP = "walk-up"
STAFF = "staff"
#: the Timed Up and Go's id among a visit's instruments (a configured battery's, a station order's):
#: a step of the visit given by staff, never at a walk-up (issue 34; kiosk.core.tug.visit)
TUG = "tug"
#: what every patient identifier is, whatever the site: 2-64 letters, digits, '-' or '_' with at
#: least one digit (what the store and the station's rows accept)
HOSPITAL_ID = re.compile(r"^(?=.*[0-9])[A-Za-z0-9][A-Za-z0-9_-]{1,63}$")
#: the identifier rule where staff type one (the station's order form, the kiosk's "Start a
#: visit"), matched whole: digit-dominant, at most four letters and only in front, so a name with
#: digits ("MariaLopez19450312", issue 32) is refused. A site sets its own (``patient_id_pattern``
#: in the kiosk's configuration, ``--patient-id-pattern`` for the station), e.g. ``NHC-[0-9]{7}``.
DEFAULT_ID_PATTERN = r"(?:[A-Za-z]{1,4}[-_]?)?[0-9][0-9_-]*"
#: names a site's pattern must refuse, or it is not an identifier rule
NAMES = ("MariaLopez19450312", "Maria Lopez", "LOPEZ", "Jose.Garcia", "ONeill1950")


@record
class Order:
    """A visit ordered for this kiosk, as the station describes it (protocol §4)."""

    id: str
    patient_id: str
    instruments: tuple[str, ...]
    language: str
    answered_by: str
    ordered_by: str = ""
    #: how the person answering is related to the patient (the order's ``relationship`` and
    #: ``relationship_text``), None when the patient answers or the station did not say
    answerer: Answerer | None = None

    @property
    def visit(self) -> str:
        """The session's ``visit`` log entry for this order."""
        return order_visit(self.id)

    @property
    def relative(self) -> bool:
        return self.answered_by == "relative"


def order_visit(order_id: str) -> str:
    return f"order {order_id}"


def check_patient_id(value: str, pattern: str | None = DEFAULT_ID_PATTERN) -> str | None:
    """Why ``value`` is not a hospital's patient identifier (one sentence), or None: it must be
    one (:data:`HOSPITAL_ID`) and match ``pattern`` whole (None: the first rule only, for an
    identifier the station already checked)."""
    if not value:
        return "type the patient's identifier"
    if not HOSPITAL_ID.match(value):
        return (
            f"{value[:64]!r} is not a patient identifier: 2 to 64 letters, digits, '-' or '_', "
            "with at least one digit, never a name"
        )
    if pattern is not None and not re.fullmatch(pattern, value):
        rule = (
            "at most four letters in front, then digits ('-' or '_' between)"
            if pattern == DEFAULT_ID_PATTERN
            else f"the site's identifiers match {pattern}"
        )
        return f"{value[:64]!r} is not a patient identifier here: {rule}, never a name"
    return None


def pattern_problem(pattern: object) -> str | None:
    """Why ``pattern`` cannot be a site's identifier rule (one sentence), or None: it must be a
    regular expression that refuses every name of :data:`NAMES`."""
    if not isinstance(pattern, str) or not pattern or len(pattern) > 200:
        return "patient_id_pattern must be a regular expression of 1 to 200 characters, in quotes"
    try:
        compiled = re.compile(pattern)
    except re.error as exc:
        return f"patient_id_pattern is not a regular expression: {exc}"
    accepted = [name for name in NAMES if compiled.fullmatch(name)]
    if accepted:
        return f"patient_id_pattern accepts the name {accepted[0]!r}: an identifier rule must refuse names"
    return None


def parse_orders(body: Any, instruments: Sequence[str], languages: Iterable[str]) -> tuple[list[Order], list[str]]:
    """The orders of a ``GET /api/v1/orders`` answer this kiosk can run, and one sentence per entry
    it cannot (an instrument or language it does not have, a malformed entry): never half-taken."""
    found: list[Order] = []
    problems: list[str] = []
    entries = body.get("orders") if isinstance(body, Mapping) else None
    if not isinstance(entries, list):
        return [], ["the station's answer has no 'orders' list"]
    known_languages = set(languages)
    for index, entry in enumerate(entries):
        where = f"orders[{index}]"
        if not isinstance(entry, Mapping):
            problems.append(f"{where}: not an object")
            continue
        order_id, patient = entry.get("id"), entry.get("patient_id")
        wanted = entry.get("instruments")
        language, answered_by = entry.get("language"), entry.get("answered_by", "patient")
        if not isinstance(order_id, str) or not order_id or not isinstance(patient, str):
            problems.append(f"{where}: without an id or a patient identifier")
        elif check_patient_id(patient, None):  # the station's own rule was applied where it was typed
            problems.append(f"{where} ({order_id}): {check_patient_id(patient, None)}")
        elif not isinstance(wanted, list) or not wanted or any(i not in (*instruments, TUG) for i in wanted):
            problems.append(f"{where} ({order_id}): instruments {wanted!r}: this kiosk gives {', '.join(instruments)}")
        elif all(i == TUG for i in wanted):
            problems.append(f"{where} ({order_id}): the Timed Up and Go alone: this kiosk gives it within a visit")
        elif language not in known_languages:
            problems.append(f"{where} ({order_id}): language {language!r} is not one this kiosk speaks")
        elif answered_by not in ("patient", "relative", "caregiver"):
            problems.append(f"{where} ({order_id}): answered_by {answered_by!r}")
        else:
            try:
                related = _answerer(entry)
            except ValueError as exc:
                problems.append(f"{where} ({order_id}): {exc}")
                continue
            ordered_by = str(entry.get("ordered_by") or "")
            found.append(Order(order_id, patient, tuple(wanted), language, answered_by, ordered_by, related))
    return found, problems


#: why a visit the ward cancelled while it ran ended (its session's log and the station's trail)
CANCELLED = "the visit was cancelled at the ward station"


def parse_cancelled(body: Any) -> tuple[str, ...]:
    """The ids in a ``GET /api/v1/orders`` answer's ``cancelled`` list (protocol §4): visits the
    ward cancelled that this kiosk may be running; anything but a list of ids is none."""
    entries = body.get("cancelled") if isinstance(body, Mapping) else None
    if not isinstance(entries, list):
        return ()
    return tuple(e for e in entries if isinstance(e, str) and e)


def runs_cancelled(visit: str | None, order_ids: Iterable[str]) -> bool:
    """The session whose ``visit`` entry this is runs one of the cancelled orders."""
    return visit is not None and visit in {order_visit(i) for i in order_ids}


def _answerer(entry: Mapping[str, Any]) -> Answerer | None:
    """An order's ``relationship`` (and ``relationship_text``), or None without one."""
    if entry.get("relationship") is None:
        return None
    return answerer(entry["relationship"], entry.get("relationship_text") or "")


def visit_of(log: Iterable[Any]) -> str | None:
    """How a stored session began, from its log entries (``kind``, ``detail``): "order <id>",
    "staff", "walk-up", or None for a session stored before visits were recorded."""
    return next((entry.detail for entry in log if entry.kind == "visit"), None)


class VisitDesk:
    """What the kiosk's welcome offers and how a visit's session is made, for the app to follow.

    ``make_session(patient_id, language, answered_by, visit, instruments=ids)`` builds a fresh
    session (``instruments``: an order's, else the kiosk's battery);
    ``walk_up`` says whether anyone may start a test at the welcome (the site's config). The app
    tells the desk the orders the station lists (:meth:`set_orders`) and asks it what to show
    (:meth:`holds_welcome`) and which session to start.
    """

    def __init__(self, make_session: Any, *, walk_up: bool = True, id_pattern: str = DEFAULT_ID_PATTERN) -> None:
        self._make = make_session
        self.walk_up = walk_up
        #: the site's identifier rule (:func:`check_patient_id`)
        self.id_pattern = id_pattern
        #: the visits ordered for this kiosk, oldest first
        self.ready: tuple[Order, ...] = ()
        #: the station's entries this kiosk cannot run, for the clinician screen
        self.problems: tuple[str, ...] = ()
        #: staff chose a walk-up although visits wait (until the next session)
        self.walk_up_chosen = False

    def set_orders(self, orders: Sequence[Order], problems: Sequence[str] = ()) -> bool:
        """The station's current list; True when it changed what the welcome shows."""
        changed = tuple(orders) != self.ready
        self.ready, self.problems = tuple(orders), tuple(problems)
        return changed

    def holds_welcome(self) -> bool:
        """The welcome is replaced by the visit screen: visits wait (and staff did not choose a
        walk-up), or walk-ups are not allowed here. Nothing a patient presses starts a test then."""
        return not self.walk_up or (bool(self.ready) and not self.walk_up_chosen)

    def choose_walk_up(self) -> bool:
        """Staff chose a test without an order; False where walk-ups are not allowed."""
        self.walk_up_chosen = self.walk_up
        return self.walk_up

    def next_visit(self) -> None:
        """A new session replaced the last one: back to offering the ordered visits."""
        self.walk_up_chosen = False

    def for_order(self, order: Order) -> Any:
        """The session of an ordered visit: its patient, language, who answers and its instruments
        (the first one's session; the others follow it in the order's order)."""
        self.ready = tuple(o for o in self.ready if o.id != order.id)
        return self._make(
            order.patient_id,
            order.language,
            order.answered_by,
            order.visit,
            instruments=order.instruments,
            answerer=order.answerer,
        )

    def for_staff(
        self, patient_id: str, language: str, relative: bool, answerer: Answerer | None = None
    ) -> tuple[Any, str | None]:
        """The session of a visit staff start by typing the identifier: (session, None), or
        (None, why not); ``answerer``: how the relative answering is related to the patient."""
        patient_id = patient_id.strip()
        why = check_patient_id(patient_id, self.id_pattern)
        if why:
            return None, why
        answered_by = "relative" if relative else "patient"
        return self._make(patient_id, language, answered_by, STAFF, answerer=answerer), None
