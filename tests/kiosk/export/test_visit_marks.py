"""Every result says how its visit began (ordered, started by staff, walk-up), in the kiosk's own
store and in its exports: a walk-up is never mistaken for an ordered visit downstream."""

from __future__ import annotations

import csv
import io

import pytest

from kiosk.commands.replay import load_script, run_script
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.visits import visit_of
from kiosk.export import csv_text, fhir_response, wide_csv_text
from kiosk.store.database import Store

SCRIPT = "recordings/patients/barthel1.yaml"


@pytest.mark.parametrize("visit", ["walk-up", "staff", "order order-1a2b3c4d5e6f"])
def test_the_visit_is_stored_and_exported(tmp_path, visit):
    q = load_questionnaire()
    with Store.open(tmp_path) as store:
        session_id = run_script(load_script(SCRIPT, q), q, store=store, visit=visit).session.id
        stored = store.session(session_id)
    assert visit_of(stored.log) == visit
    rows = list(csv.DictReader(io.StringIO(csv_text(q, [stored]))))
    assert {row["visit"] for row in rows} == {visit}
    (wide,) = csv.DictReader(io.StringIO(wide_csv_text(q, [stored])))
    assert wide["visit"] == visit
    (tag,) = fhir_response(q, stored)["meta"]["tag"]
    assert (tag["system"], tag["code"], tag["display"]) == ("urn:barthel-kiosk:visit", visit.split(" ")[0], visit)


def test_a_session_stored_before_visits_existed_exports_a_blank_visit(tmp_path):
    q = load_questionnaire()
    with Store.open(tmp_path) as store:
        stored = store.session(run_script(load_script(SCRIPT, q), q, store=store).session.id)
    assert visit_of(stored.log) is None
    assert {row["visit"] for row in csv.DictReader(io.StringIO(csv_text(q, [stored])))} == {""}
    assert "tag" not in fhir_response(q, stored).get("meta", {})
