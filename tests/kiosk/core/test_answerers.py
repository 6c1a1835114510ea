"""Who answers an instrument (``answered_by: caregiver`` at its top): never started by a walk-up
patient, who is told in calm words; answered by a caregiver, with the relationship logged."""

from __future__ import annotations

import pytest

from kiosk.core.answerers import Answerer, answerer, answerer_of, walk_up_instruments
from kiosk.core.clock import SimClock
from kiosk.core.questionnaire import QuestionnaireError, load_questionnaire
from kiosk.core.questionnaire.definition import canonical, questionnaire_from
from kiosk.core.session import AnsweredBy, Phase, Prompt
from kiosk.core.visits import parse_orders
from kiosk.store.database import Store
from tests.kiosk.battery_instruments import write_mini
from tests.kiosk.core.answerer_instruments import caregiver_instrument, session_of


def test_an_instrument_says_who_answers_it_and_its_capture_keeps_it(tmp_path):
    carer = caregiver_instrument(tmp_path)
    assert carer.answered_by == "caregiver"
    assert questionnaire_from(canonical(carer)).answered_by == "caregiver"
    assert load_questionnaire().answered_by == "patient"  # the default: every shipped instrument
    path = write_mini(tmp_path, id="other")
    path.write_text("answered_by: neighbour\n" + path.read_text())
    with pytest.raises(QuestionnaireError) as caught:
        load_questionnaire(path)
    assert str(caught.value).startswith(f"{path}:1:14: answered_by: 'neighbour' is not one of")


def test_a_walk_up_patient_never_starts_a_caregiver_instrument(tmp_path):
    clock = SimClock()
    with Store.open(tmp_path / "data") as store:
        session = session_of(caregiver_instrument(tmp_path), clock, visit="walk-up", store=store)
        said: list = []
        session.subscribe(said.append)
        clock.set(5)
        session.start()
        assert session.phase is Phase.WELCOME and list(store.sessions()) == []  # nothing started or stored
    (prompt,) = [e for e in said if isinstance(e, Prompt)]
    assert (prompt.key, prompt.text) == (
        "caregiver_only",
        "These questions are for the person who looks after you. Please ask a member of staff.",
    )
    assert session.snapshot().prompt == prompt  # what the welcome screen draws instead of its lines


@pytest.mark.parametrize("visit", ["order order-1a2b3c4d5e6f", "staff"])
def test_an_ordered_or_staff_visit_starts_it_answered_by_the_caregiver(tmp_path, visit):
    clock = SimClock()
    with Store.open(tmp_path / "data") as store:
        carer = caregiver_instrument(tmp_path)
        session = session_of(carer, clock, visit=visit, answerer=Answerer("daughter"), store=store)
        clock.set(5)
        session.start()
        assert session.phase is Phase.EXPLANATION
        stored = store.session(session.id)
    assert session.answered_by is AnsweredBy.CAREGIVER and stored.answered_by is AnsweredBy.CAREGIVER
    assert answerer_of(stored.log) == Answerer("daughter")


def test_the_patient_answering_logs_no_answerer(tmp_path):
    clock = SimClock()
    with Store.open(tmp_path) as store:
        session = session_of(load_questionnaire(), clock, visit="staff", answerer=Answerer("daughter"), store=store)
        session.start()
        stored = store.session(session.id)
    assert stored.answered_by is AnsweredBy.PATIENT and answerer_of(stored.log) is None


def test_a_walk_up_battery_keeps_only_the_patients_instruments(tmp_path):
    carer = caregiver_instrument(tmp_path)
    assert walk_up_instruments([load_questionnaire(), carer]) == ("barthel",)
    assert walk_up_instruments([carer]) == ()


def test_the_relationship_is_a_coded_choice_or_free_text():
    assert answerer("spouse").code.code == "SPS"
    assert answerer("other", " lodger ").display == "lodger"
    assert answerer("paid carer").code.system == "urn:barthel-kiosk:relationship"
    for bad, why in [
        (("cousin",), "relationship 'cousin' is not one of spouse, daughter"),
        (("other",), 'relationship "other" needs the text'),
        (("son", "x" * 61), "at most 60 characters"),
        (("son", "a\nb"), "one line"),
    ]:
        with pytest.raises(ValueError, match=why):
            answerer(*bad)


def test_an_order_carries_the_relationship_or_is_refused_in_one_sentence():
    entry = {"id": "o1", "patient_id": "HC123", "instruments": ["carer"], "language": "en"}
    orders, problems = parse_orders(
        {
            "orders": [
                entry | {"answered_by": "relative", "relationship": "other", "relationship_text": "lodger"},
                entry | {"id": "o2", "relationship": "cousin"},
            ]
        },
        ["carer"],
        ["en"],
    )
    assert [o.answerer for o in orders] == [Answerer("other", "lodger")]
    assert problems == ["orders[1] (o2): relationship 'cousin' is not one of " + ", ".join(_names())]


def _names() -> list[str]:
    from kiosk.core.answerers import RELATIONSHIPS

    return list(RELATIONSHIPS)
