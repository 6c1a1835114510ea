"""LHC-Forms in real Chromium renders exported format v2 instruments with their responses and
computes, from the exported ``calculatedExpression``s alone (the response it gets has the
answers, not the total), the total the kiosk computed: a FHIRPath
formula over a staff-entered number, subscales, negative points, yes/no items."""

from __future__ import annotations

import pytest

from kiosk.export import fhir_questionnaire, result
from kiosk.export.fhir import response_of
from tests.kiosk.core.instruments_v2 import GDS, MEASURED, MIXED, STAFFED, load

from .test_formula_export import SITE, stored
from .test_lforms import PATIENCE_MS, RENDER, lforms_page  # noqa: F401 - the page fixture

pytestmark = pytest.mark.slow


@pytest.mark.parametrize(
    ("text", "options", "values", "language", "computed"),
    [
        (STAFFED, {"recall": 3, "orientation": 2, "judged": 2}, {"education": 6}, "en", {"total": 3}),
        (STAFFED, {"recall": 1, "orientation": 3, "judged": 1}, {"education": 15}, "es", {"total": 2}),
        (MIXED, {"pain": 1, "steps": 6, "sleep": 2, "appetite": 1}, {}, "en", {"total": 5, "body": 3, "rest": 2}),
        (MIXED, {"pain": 1, "steps": 1, "sleep": 1, "appetite": 1}, {}, "es", {"total": -2, "body": -2, "rest": 0}),
        (GDS, {"satisfied": 2, "bored": 1, "helpless": 2}, {}, "en", {"total": 2}),
        (MEASURED, {"intake": 3}, {"weight": 60.5, "height": 170.0}, "en", {"total": 3}),
    ],
)
def test_lhc_forms_computes_the_kiosks_total_and_subscales(
    lforms_page,
    tmp_path,
    text,
    options,
    values,
    language,
    computed,
):
    page, errors = lforms_page
    q = load(tmp_path, text)
    r = result(q, stored(q, options, language), values=values)
    assert r.complete and r.score.total == computed["total"]
    assert {k: v for k, v in r.score.subscales.items()} == {k: v for k, v in computed.items() if k != "total"}
    questionnaire = fhir_questionnaire(q, language, SITE)
    response = response_of(q, r, SITE)
    assert {k: [{"valueInteger": v}] for k, v in computed.items()} == {
        i["linkId"]: i["answer"] for i in response["item"] if i["linkId"] in computed
    }
    # LHC-Forms gets the answers only: what it shows for the total and subscales it computed itself
    answers_only = response | {"item": [i for i in response["item"] if i["linkId"] not in computed]}
    page.set_default_timeout(PATIENCE_MS)
    rendered = page.evaluate(RENDER, [questionnaire, answers_only])
    assert not errors, errors
    for link, value in computed.items():
        assert rendered["shown"][link] == str(value), (link, rendered["shown"])
    for item, number in values.items():
        assert float(rendered["shown"][item]) == number, (item, rendered["shown"][item])
    for item, number in options.items():
        option = q.item(item).option(number)
        assert rendered["shown"][item].endswith(f" - {option.points}"), (item, rendered["shown"][item])
    back = {i["linkId"]: i.get("answer") for i in rendered["back"]["item"]}
    assert {k: back.get(k) for k in computed} == {k: [{"valueInteger": v}] for k, v in computed.items()}


@pytest.mark.parametrize(
    ("name", "language", "pick"),
    [
        ("barthel", "en", 0),
        ("lawton", "en", 1),
        ("lawton", "fr", 3),
        ("gds15", "en", 0),
        ("gds15", "de", 1),
        ("sarc_f", "es", 2),
    ],
)
def test_lhc_forms_computes_each_shipped_instruments_total(lforms_page, name, language, pick):
    """Each instrument the kiosk ships, exported with a response: LHC-Forms computes the total the
    kiosk computed from the answers alone (``pick`` varies which option each item gets)."""
    from kiosk.core.questionnaire import bundled_path, load_questionnaire

    page, errors = lforms_page
    q = load_questionnaire(bundled_path(f"{name}.yaml"))
    options = {item.id: (n + pick) % len(item.options) + 1 for n, item in enumerate(q.patient_items)}
    r = result(q, stored(q, options, language))
    assert r.complete
    questionnaire = fhir_questionnaire(q, language, SITE)
    response = response_of(q, r, SITE)
    (total_link,) = [i["linkId"] for i in questionnaire["item"] if i["linkId"] not in options]
    answers_only = response | {"item": [i for i in response["item"] if i["linkId"] != total_link]}
    page.set_default_timeout(PATIENCE_MS)
    rendered = page.evaluate(RENDER, [questionnaire, answers_only])
    assert not errors, errors
    assert rendered["shown"][total_link] == str(r.score.total), (name, rendered["shown"][total_link])
