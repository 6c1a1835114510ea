"""Every complete result has a total Observation (issue 36): the instrument's standard code where
it has one (the Barthel's LOINC 96761-2), else the site's own code system with the instrument's
id and title (the Lawton, the SARC-F, an instrument a site writes). Real replays in a real store;
the Bundles checked by the R4 schema and fhir.resources."""

from __future__ import annotations

from pathlib import Path

import pytest

from kiosk.commands.replay import load_script, run_script
from kiosk.core.questionnaire import bundled_path, load_questionnaire
from kiosk.export import ExportSite, transaction_bundle
from kiosk.store.database import Store
from tests.kiosk.export.standard import check_fhir

SITE = ExportSite(site="hosp-north", kiosk_id="ward3-bed2")

#: an instrument as a site writes one: no code of any kind
SITE_INSTRUMENT = """\
id: walking
version: "1"
source: "A test instrument (no publication)"
title: {en: Walking}
languages: [en]
timing: {attempt_window_s: 20}
bands:
  default: main
  sets:
    main:
      source: test cut-offs
      ranges:
        - {id: low, min: 0, max: 1, label: {en: Low}}
        - {id: high, min: 2, max: 4, label: {en: High}}
items:
""" + "".join(
    f"""\
  - id: {item}
    text: {{en: "{item.title()}?"}}
    spoken: {{en: "{item.title()}?"}}
    options:
      - {{points: 2, label: {{en: "Alone"}}}}
      - {{points: 0, label: {{en: "Not at all"}}}}
"""
    for item in ("steps", "stairs")
)


def _observations(q, tmp_path: Path, answered: list[str]) -> list[dict]:
    lines = [
        f"  - {{item: {i.id}, attempt: 1, channel: touch, option: 1, after: 2}}"
        if i.id in answered
        else f"  - {{item: {i.id}, attempt: none}}"
        for i in q.items
    ]
    tmp_path.mkdir(exist_ok=True)
    script = tmp_path / "patient.yaml"
    script.write_text("patient: P-TOTAL\nfamiliarisation: false\nquestions:\n" + "\n".join(lines) + "\n", "utf-8")
    with Store.open(tmp_path / "data") as store:
        stored = store.session(run_script(load_script(script, q), q, store=store).session.id)
    bundle = transaction_bundle(q, [stored], None, SITE)
    check_fhir(bundle)
    return [e["resource"] for e in bundle["entry"] if e["resource"]["resourceType"] == "Observation"]


@pytest.mark.parametrize("name", ["lawton.yaml", "sarc_f.yaml"])
def test_a_shipped_instrument_without_a_standard_total_code_exports_its_total(name, tmp_path):
    q = load_questionnaire(bundled_path(name))
    assert q.total_code is None  # none we could confirm: the site's code stands in
    (total,) = _observations(q, tmp_path, [i.id for i in q.items])
    assert total["code"]["coding"] == [
        {"system": "urn:barthel-kiosk:hosp-north:total", "code": q.id, "display": f"{q.title['en']} total"}
    ]
    assert total["status"] == "preliminary"
    assert total["valueQuantity"]["value"] == sum(i.options[0].points for i in q.items)


def test_a_site_instrument_exports_its_total_and_an_incomplete_one_none(tmp_path):
    (tmp_path / "walk.yaml").write_text(SITE_INSTRUMENT, encoding="utf-8")
    q = load_questionnaire(tmp_path / "walk.yaml")
    assert q.total_code is None and not any(i.staff for i in q.items)
    (total,) = _observations(q, tmp_path / "whole", [i.id for i in q.items])
    assert total["code"]["coding"][0]["code"] == "walking" and total["code"]["text"] == "Walking: Total score"
    assert _observations(q, tmp_path / "part", ["steps"]) == []  # a partial sum is never charted as a total


def test_the_barthel_keeps_its_loinc_code(tmp_path):
    q = load_questionnaire()
    (total,) = _observations(q, tmp_path, [i.id for i in q.items])
    assert total["code"]["coding"][0]["system"] == "http://loinc.org"
    assert total["code"]["coding"][0]["code"] == "96761-2"
