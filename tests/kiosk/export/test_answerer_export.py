"""Who answered for the patient, exported: a caregiver instrument's response names a contained
RelatedPerson with the relationship (coded where the kiosk has a code) as its ``source``, and the
CSVs have it in their ``answerer`` column."""

from __future__ import annotations

import csv
import io

import pytest

from kiosk.core.answerers import Answerer
from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.clock import SimClock
from kiosk.export import csv_text, fhir_response, wide_csv_text
from kiosk.store.database import Store
from tests.kiosk.core.answerer_instruments import caregiver_instrument, session_of
from tests.kiosk.export.standard import check_fhir


def _answered(tmp_path, answerer: Answerer | None):
    """A caregiver instrument's session of an ordered visit, both items answered, as stored."""
    q = caregiver_instrument(tmp_path)
    clock = SimClock()
    with Store.open(tmp_path / "data") as store:
        session = session_of(q, clock, store=store, visit="order order-1a2b3c4d5e6f", answerer=answerer)
        session.start()
        session.acknowledge()
        while not session.finished and (deadline := session.next_deadline()) is not None:
            if session.snapshot().attempt is not None:
                session.handle(ChannelInput(Channel.TOUCH, option=1))
            else:
                clock.set(deadline)
                session.poll()
        assert len(store.session(session.id).answers) == 2
        return q, store.session(session.id)


@pytest.mark.parametrize(
    "answerer, relationship",
    [
        (
            Answerer("daughter"),
            {
                "coding": [
                    {
                        "system": "http://terminology.hl7.org/CodeSystem/v3-RoleCode",
                        "code": "DAUC",
                        "display": "daughter",
                    }
                ],
                "text": "daughter",
            },
        ),
        (Answerer("other", "lodger"), {"text": "lodger"}),
    ],
)
def test_the_answerer_is_a_related_person_and_a_csv_column(tmp_path, answerer, relationship):
    q, stored = _answered(tmp_path, answerer)
    response = fhir_response(q, stored)
    check_fhir(response)  # valid R4 for the official schema and fhir.resources
    (related,) = response["contained"]
    assert related["resourceType"] == "RelatedPerson" and related["patient"] == response["subject"]
    assert related["relationship"] == [relationship]
    assert response["source"] == {"reference": "#answerer", "type": "RelatedPerson", "display": "caregiver"}
    rows = list(csv.DictReader(io.StringIO(csv_text(q, [stored]))))
    assert {(row["answered_by"], row["answerer"]) for row in rows} == {("caregiver", answerer.display)}
    (wide,) = csv.DictReader(io.StringIO(wide_csv_text(q, [stored])))
    assert (wide["answered_by"], wide["answerer"]) == ("caregiver", answerer.display)


def test_without_a_recorded_relationship_the_related_person_says_none(tmp_path):
    q, stored = _answered(tmp_path, None)
    response = fhir_response(q, stored)
    check_fhir(response)
    assert response["contained"] == [
        {"resourceType": "RelatedPerson", "id": "answerer", "patient": response["subject"]}
    ]
    assert {row["answerer"] for row in csv.DictReader(io.StringIO(csv_text(q, [stored])))} == {""}
