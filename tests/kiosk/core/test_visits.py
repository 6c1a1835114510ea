"""How a visit begins (kiosk.core.visits): the identifier rule that keeps names out, the station's orders
a kiosk can and cannot run (each refusal one sentence naming the entry), and what the welcome
shows: ordered visits first, walk-ups only where the site allows them."""

from __future__ import annotations

import pytest

from kiosk.core.visits import (
    DEFAULT_ID_PATTERN,
    Order,
    VisitDesk,
    check_patient_id,
    parse_cancelled,
    parse_orders,
    pattern_problem,
    runs_cancelled,
)


@pytest.mark.parametrize("identifier", ["NHC-0012345", "12345678", "MRN_77", "p2"])
def test_hospital_identifiers_are_taken(identifier):
    assert check_patient_id(identifier) is None


@pytest.mark.parametrize(
    "name", ["Maria Lopez", "LOPEZ", "O'Neill", "Jose.Garcia", "-123", "x" * 65, "", "MariaLopez19450312", "Lopez1945"]
)
def test_names_and_malformed_identifiers_are_refused(name):
    why = check_patient_id(name)
    assert why is not None and ("never a name" in why or "type the patient" in why)


def test_a_sites_own_pattern_is_the_rule_and_must_refuse_names():
    assert check_patient_id("NHC-0012345", r"NHC-[0-9]{7}") is None
    assert "the site's identifiers match NHC-[0-9]{7}" in check_patient_id("12345678", r"NHC-[0-9]{7}")
    assert check_patient_id("AB12CD34", r"[A-Z]{2}[0-9]{2}[A-Z]{2}[0-9]{2}") is None  # a looser site rule
    assert check_patient_id("AB 12", r".*") is not None  # never beyond what an identifier is
    assert pattern_problem(r"NHC-[0-9]{7}") is None and pattern_problem(DEFAULT_ID_PATTERN) is None
    assert "accepts the name 'MariaLopez19450312'" in pattern_problem(r"[A-Za-z0-9]+")
    assert "not a regular expression" in pattern_problem("NHC-[0-9")
    desk = VisitDesk(lambda *a, **k: a, id_pattern=r"NHC-[0-9]{7}")
    assert desk.for_staff("12345678", "en", False)[0] is None
    assert desk.for_staff("NHC-0012345", "en", False)[0] == ("NHC-0012345", "en", "patient", "staff")


def test_orders_the_kiosk_cannot_run_are_left_out_with_why():
    entry = {
        "id": "order-1",
        "patient_id": "NHC-1",
        "instruments": ["barthel"],
        "language": "es",
        "answered_by": "relative",
        "ordered_by": "nurse.kim",
    }
    body = {
        "orders": [
            entry,
            entry | {"id": "order-2", "instruments": ["moca"]},
            entry | {"id": "order-3", "language": "de"},
            entry | {"id": "order-4", "patient_id": "LOPEZ"},
            "nonsense",
        ]
    }
    found, problems = parse_orders(body, ["barthel"], ["en", "es", "fr"])
    assert found == [Order("order-1", "NHC-1", ("barthel",), "es", "relative", "nurse.kim")]
    assert [p.split(":")[0] for p in problems] == [
        "orders[1] (order-2)",
        "orders[2] (order-3)",
        "orders[3] (order-4)",
        "orders[4]",
    ]
    assert "this kiosk gives barthel" in problems[0] and "'de'" in problems[1] and "never a name" in problems[2]
    assert parse_orders({"oops": 1}, ["barthel"], ["en"]) == ([], ["the station's answer has no 'orders' list"])


def test_an_order_of_the_timed_up_and_go_is_taken_beside_the_kiosks_instruments():
    """Issue 34: the station orders the TUG as the instrument id ``tug``; every kiosk takes it
    beside a questionnaire (alone it is refused: the kiosk gives it within a visit)."""
    entry = {"id": "order-5", "patient_id": "NHC-1", "language": "en", "answered_by": "patient"}
    body = {"orders": [entry | {"instruments": ["barthel", "tug"]}, entry | {"id": "order-6", "instruments": ["tug"]}]}
    found, problems = parse_orders(body, ["barthel"], ["en"])
    assert [o.instruments for o in found] == [("barthel", "tug")]
    assert problems == ["orders[1] (order-6): the Timed Up and Go alone: this kiosk gives it within a visit"]
    found, problems = parse_orders({"orders": [entry | {"instruments": ["tug", "moca"]}]}, ["barthel"], ["en"])
    assert found == [] and "this kiosk gives barthel" in problems[0]  # an unknown one beside it is still refused


def test_the_welcome_is_held_for_ordered_visits_and_where_walk_ups_are_not_allowed():
    made = []
    # the desk's make_session: (patient, language, answered_by, visit) and an order's instruments
    desk = VisitDesk(lambda *args, **kw: made.append(args) or (*args, kw.get("instruments")), walk_up=True)
    assert not desk.holds_welcome()
    order = Order("order-1", "NHC-1", ("barthel",), "es", "relative")
    assert desk.set_orders([order]) and desk.holds_welcome()
    assert not desk.set_orders([order])  # nothing changed
    assert desk.choose_walk_up() and not desk.holds_welcome()
    desk.next_visit()
    assert desk.holds_welcome()
    assert desk.for_order(order) == ("NHC-1", "es", "relative", "order order-1", ("barthel",)) and desk.ready == ()
    assert desk.for_staff("Maria Lopez", "en", False)[0] is None
    assert desk.for_staff(" NHC-2 ", "en", True)[0] == ("NHC-2", "en", "relative", "staff", None)
    closed = VisitDesk(lambda *args: args, walk_up=False)
    assert closed.holds_welcome() and not closed.choose_walk_up() and closed.holds_welcome()


def test_the_cancelled_orders_of_a_poll_are_read_and_matched_to_the_running_visit():
    assert parse_cancelled({"orders": [], "cancelled": ["order-1", 7, "", None, "order-2"]}) == ("order-1", "order-2")
    for junk in ({"orders": []}, {"cancelled": "order-1"}, ["order-1"], None):
        assert parse_cancelled(junk) == ()  # a station from before, or a wrong answer: nothing ends
    assert runs_cancelled("order order-1", ("order-2", "order-1"))
    assert not runs_cancelled("walk-up", ("order-1",)) and not runs_cancelled(None, ("order-1",))
    assert not runs_cancelled("order order-10", ("order-1",))
