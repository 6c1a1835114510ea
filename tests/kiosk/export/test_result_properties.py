"""Whatever the session and the clinician's review, what the FHIR export says cannot be misread:
a total exists exactly when every item has an answer and is their sum, a `completed` or `amended`
response has every required item, and only a signed-off result is final."""

from __future__ import annotations

import csv
import io

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kiosk.core.review import Correction, Review, ReviewState
from kiosk.export import (
    ExportSite,
    csv_text,
    fhir_response,
    fhir_total,
    transaction_bundle,
)
from tests.kiosk.core.helpers import QUESTIONNAIRE

from .standard import check_fhir

SITE = ExportSite(site="hosp-north", kiosk_id="ward3-bed2")
PATIENTS = ["TB-0001", "TB-0004", "TB-0005", "TB-0006", "P-ES-0001", "P-FR-0003"]


@st.composite
def reviews(draw):
    state = draw(st.sampled_from(list(ReviewState)))
    items = draw(st.lists(st.sampled_from(QUESTIONNAIRE.items), unique_by=lambda i: i.id, max_size=4))
    corrections = tuple(
        Correction(
            item.id, draw(st.integers(1, len(item.options))), None, "checked", "nurse.kim", f"2026-11-23T15:0{n}:00Z"
        )
        for n, item in enumerate(items)
    )
    signed = state != ReviewState.UNREVIEWED
    return Review(state, corrections, "dr.lopez" if signed else None, "2026-11-23T15:09:00Z" if signed else None)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(patient=st.sampled_from(PATIENTS), review=reviews())
def test_the_export_never_states_a_total_or_a_state_it_does_not_have(replayed, patient, review):
    stored = replayed[patient]
    options = review.options({a.item_id: a.option for a in stored.answers})
    complete = len(options) == len(QUESTIONNAIRE.items)
    response = fhir_response(QUESTIONNAIRE, stored, review, SITE)
    check_fhir(response)
    total = next((i for i in response.get("item", []) if i["linkId"] == "total"), {}).get("answer")
    expected = sum(QUESTIONNAIRE.item(i).option(o).points for i, o in options.items())
    assert total == ([{"valueInteger": expected}] if complete else None)
    answered = {i["linkId"] for i in response.get("item", []) if i["linkId"] != "total"}
    assert all(i.get("answer") for i in response.get("item", []))  # no unanswered item, as SDC does
    assert answered == set(options)
    if response["status"] in ("completed", "amended"):
        assert complete  # every required item answered: never a `completed` form with gaps
    else:
        assert not complete and response["status"] in ("in-progress", "stopped")
    assert ("extension" in response) == review.final  # a signature only after a sign-off
    recorded = {a.item_id: a.option for a in stored.answers}
    changed = any(recorded.get(c.item_id) != c.option for c in review.corrections)
    assert response["author"]["type"] == "Device"  # the kiosk recorded them; each change is a Provenance
    assert (response["status"] == "amended") == (changed and complete)
    observation = fhir_total(QUESTIONNAIRE, stored, review, SITE)
    assert (observation is not None) == (complete or review.final)  # signed incomplete: a total with none
    if observation is not None:
        check_fhir(observation)
        if complete:
            assert observation["valueQuantity"]["value"] == expected and "dataAbsentReason" not in observation
        else:
            assert "valueQuantity" not in observation and observation["dataAbsentReason"]["text"]
        assert (observation["status"] == "preliminary") == (not review.final)
    bundle = transaction_bundle(QUESTIONNAIRE, [stored], [review], SITE)
    check_fhir(bundle)  # the Provenance of every change too
    provenances = [e for e in bundle["entry"] if e["resource"]["resourceType"] == "Provenance"]
    assert len(provenances) == len(review.corrections)
    assert all(e["resource"]["agent"][0]["who"]["identifier"]["value"] == "nurse.kim" for e in provenances)
    requests = {e["resource"]["resourceType"]: e["request"]["method"] for e in bundle["entry"]}
    assert requests["QuestionnaireResponse"] == ("PUT" if review.final else "POST")
    # one story: the CSV's review state is what the response and the Observation say
    (state,) = {
        row["review_state"] for row in csv.DictReader(io.StringIO(csv_text(QUESTIONNAIRE, [stored], [review], SITE)))
    }
    assert (state in ("corrected", "amended")) == changed_now(stored, options)
    if complete:
        assert (response["status"] == "amended") == (state in ("corrected", "amended"))
        assert observation["status"] == {"amended": "amended", "signed_off": "final"}.get(state, "preliminary")


def changed_now(stored, options) -> bool:
    return options != {a.item_id: a.option for a in stored.answers}
