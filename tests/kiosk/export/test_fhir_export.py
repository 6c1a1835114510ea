"""FHIR R4 export of replayed sessions, checked against the standard (official JSON schema, the
fhir.resources models) and for what it means: status, totals, review, languages, identity."""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from urllib.parse import unquote

import pytest
from pydantic import ValidationError

from kiosk.core.questionnaire import check_questionnaire_file, load_questionnaire
from kiosk.core.review import Correction, Review, ReviewState
from kiosk.export import (
    ORDINAL_VALUE,
    SIGNATURE,
    ExportSite,
    fhir_questionnaire,
    fhir_response,
    fhir_total,
    questionnaire_bundle,
    questionnaire_version,
    transaction_bundle,
)
from kiosk.store.database import Store
from tests.kiosk.core.helpers import QUESTIONNAIRE, TIMING, make_rig

from .conftest import PATIENTS, ROOT
from .standard import check_fhir, parse_r4, schema_errors

SITE = ExportSite(
    site="hosp-north",
    kiosk_id="ward3-bed2",
    patient_system="https://hosp-north.example/sid/kiosk-patient",
    questionnaire_url="https://hosp-north.example/fhir/Questionnaire/barthel",
)
AT = "2026-11-23T15:02:11Z"


def signed(state: ReviewState = ReviewState.SIGNED_OFF, *corrections: Correction) -> Review:
    return Review(state=state, corrections=corrections, signed_by="dr.lopez", signed_at=AT)


def fill(item: str, option: int, previous: int | None = None) -> Correction:
    return Correction(item, option, previous, "asked the patient again", "dr.lopez", "2026-11-23T15:00:00Z")


def entries(bundle, kind):
    return [e for e in bundle["entry"] if e["resource"]["resourceType"] == kind]


def total_answer(response):
    return next((i for i in response.get("item", []) if i["linkId"] == "total"), {}).get("answer")


def test_every_replayed_session_exports_as_valid_r4_in_one_transaction_bundle(replayed):
    bundle = transaction_bundle(QUESTIONNAIRE, list(replayed.values()), site=SITE)
    check_fhir(bundle)
    assert bundle["type"] == "transaction"
    assert len(entries(bundle, "QuestionnaireResponse")) == len(replayed) == len(PATIENTS)
    assert {e["resource"]["language"] for e in entries(bundle, "Questionnaire")} == {"en", "es", "fr"}
    for language in ("en", "es", "fr"):
        check_fhir(fhir_questionnaire(QUESTIONNAIRE, language, SITE))
    check_fhir(questionnaire_bundle(QUESTIONNAIRE, SITE))
    for stored in replayed.values():
        check_fhir(fhir_response(QUESTIONNAIRE, stored, site=SITE))


def test_an_incomplete_session_has_no_total_anywhere_and_is_not_completed(replayed):
    stored = replayed["TB-0004"]  # grooming and bladder not answered: 65 points from 8 items
    response = fhir_response(QUESTIONNAIRE, stored, site=SITE)
    assert response["status"] == "in-progress"
    assert total_answer(response) is None
    assert sum("answer" in i for i in response["item"]) == 8
    assert {i["linkId"] for i in response["item"]} & {"grooming", "bladder", "total"} == set()  # left out, as SDC does
    assert fhir_total(QUESTIONNAIRE, stored, site=SITE) is None
    bundle = transaction_bundle(QUESTIONNAIRE, [stored], site=SITE)
    assert not entries(bundle, "Observation")
    assert not any(key in json.dumps(bundle) for key in ("valueInteger", "valueQuantity"))  # no total at all


def test_an_abandoned_session_is_stopped(tmp_path):
    store = Store.open(tmp_path / "data")
    rig = make_rig(store=store)
    rig.at(5)
    rig.session.start()
    rig.session.acknowledge()
    rig.run_until(5 + 2 * TIMING["attempt_window_s"] + TIMING["between_questions_s"])
    store.abandon(rig.session.id)
    response = fhir_response(QUESTIONNAIRE, store.session(rig.session.id), site=SITE)
    check_fhir(response)
    assert response["status"] == "stopped" and total_answer(response) is None


def test_a_complete_unreviewed_session_is_completed_with_a_preliminary_total(replayed):
    stored = replayed["TB-0001"]
    bundle = transaction_bundle(QUESTIONNAIRE, [stored], site=SITE)
    response = entries(bundle, "QuestionnaireResponse")[0]
    observation = entries(bundle, "Observation")[0]
    assert response["resource"]["status"] == "completed" and total_answer(response["resource"]) == [
        {"valueInteger": 100}
    ]
    assert "extension" not in response["resource"]  # no signature: nobody signed it off
    assert "meta" not in response["resource"]  # a patient's session, not test data
    total = observation["resource"]
    assert total["status"] == "preliminary"
    assert total["code"]["coding"] == [
        {"system": "http://loinc.org", "code": "96761-2", "display": "Total score Barthel Index"}
    ]
    assert total["valueQuantity"]["value"] == 100
    assert total["derivedFrom"][0]["reference"] == response["fullUrl"]
    assert total["interpretation"][0]["coding"][0]["code"] == "independent"
    assert "shah" in total["interpretation"][0]["text"]  # the band set is recorded
    assert response["request"]["method"] == observation["request"]["method"] == "POST"


def test_a_signed_off_result_is_final_and_carries_who_signed_and_when(replayed):
    stored = replayed["TB-0002"]
    response = fhir_response(QUESTIONNAIRE, stored, signed(), SITE)
    check_fhir(response)
    assert response["status"] == "completed"
    signature = response["extension"][0]
    assert signature["url"] == SIGNATURE
    assert signature["valueSignature"]["who"]["display"] == "dr.lopez"
    assert signature["valueSignature"]["when"] == "2026-11-23T15:02:11+00:00"
    assert response["author"]["type"] == "Device"  # the kiosk recorded these answers
    total = fhir_total(QUESTIONNAIRE, stored, signed(), SITE)
    check_fhir(total)
    assert total["status"] == "final" and total["performer"][0]["identifier"] == {
        "system": "urn:barthel-kiosk:station:staff",
        "value": "dr.lopez",
    }
    assert signature["valueSignature"]["who"]["identifier"]["value"] == "dr.lopez"
    bundle = transaction_bundle(QUESTIONNAIRE, [stored], [signed()], SITE)
    check_fhir(bundle)
    request = entries(bundle, "QuestionnaireResponse")[0]["request"]
    assert request["method"] == "PUT" and request["url"].startswith("QuestionnaireResponse?identifier=")


def test_a_clinician_completing_an_incomplete_session_makes_it_amended_with_a_total(replayed):
    stored = replayed["TB-0004"]
    review = signed(ReviewState.AMENDED, fill("grooming", 2), fill("bladder", 3))
    response = fhir_response(QUESTIONNAIRE, stored, review, SITE)
    check_fhir(response)
    assert response["status"] == "amended"
    assert total_answer(response) == [{"valueInteger": 80}]  # 65 + 5 + 10
    assert response["author"]["type"] == "Device"  # the kiosk recorded the other answers; changes are Provenance
    assert response["authored"] == "2026-11-23T15:00:00+00:00"
    total = fhir_total(QUESTIONNAIRE, stored, review, SITE)
    check_fhir(total)
    assert total["status"] == "amended" and total["valueQuantity"]["value"] == 80
    assert [n["text"] for n in total["note"]] == [
        "grooming: option none -> 2 (asked the patient again)",
        "bladder: option none -> 3 (asked the patient again)",
    ]


def test_a_sign_off_of_an_incomplete_result_stays_without_a_total(replayed):
    response = fhir_response(QUESTIONNAIRE, replayed["TB-0006"], signed(), SITE)
    check_fhir(response)
    assert response["status"] == "stopped" and total_answer(response) is None
    # a final Observation without a value, saying why (R4 obs-6), never a partial sum
    total = fhir_total(QUESTIONNAIRE, replayed["TB-0006"], signed(), SITE)
    check_fhir(total)
    assert total["status"] == "final" and "valueQuantity" not in total and "interpretation" not in total
    assert total["dataAbsentReason"]["coding"][0]["code"] == "unknown"
    assert total["dataAbsentReason"]["text"].startswith("signed off incomplete (not answered: ")


def test_responses_match_their_questionnaire_word_for_word_in_every_language(replayed):
    bundle = transaction_bundle(QUESTIONNAIRE, list(replayed.values()), site=SITE)
    questionnaires = {
        f"{e['resource']['url']}|{e['resource']['version']}": e["resource"] for e in entries(bundle, "Questionnaire")
    }
    for entry in entries(bundle, "QuestionnaireResponse"):
        response = entry["resource"]
        questionnaire = questionnaires[response["questionnaire"]]
        assert questionnaire["language"] == response["language"]
        items = {i["linkId"]: i for i in questionnaire["item"]}
        for item in response["item"]:
            assert item["text"] == items[item["linkId"]]["text"]
            for answer in item.get("answer", []):
                if "valueCoding" in answer:
                    options = [o["valueCoding"] for o in items[item["linkId"]]["answerOption"]]
                    assert any(
                        all(o[k] == answer["valueCoding"][k] for k in ("system", "code", "display")) for o in options
                    )
    spanish = fhir_questionnaire(QUESTIONNAIRE, "es", SITE)
    feeding = spanish["item"][0]
    translations = {
        t["extension"][0]["valueCode"]: t["extension"][1]["valueString"] for t in feeding["_text"]["extension"]
    }
    assert translations == {
        "en": QUESTIONNAIRE.item("feeding").text["en"],
        "fr": QUESTIONNAIRE.item("feeding").text["fr"],
        "de": QUESTIONNAIRE.item("feeding").text["de"],
    }


def test_answers_carry_loinc_answer_codes_and_points_on_the_option_not_the_code():
    questionnaire = fhir_questionnaire(QUESTIONNAIRE, "en", SITE)
    items = {i["linkId"]: i for i in questionnaire["item"]}
    independent = [
        (link, o)
        for link, i in items.items()
        for o in i.get("answerOption", [])
        if o["valueCoding"]["code"] == "LA12302-8"
    ]
    assert {link for link, _ in independent} == {"feeding", "transfers", "stairs"}
    assert {o["extension"][1]["valueDecimal"] for _, o in independent} == {10, 15}  # same code, other points
    assert all(o["extension"][1]["url"] == ORDINAL_VALUE for i in items.values() for o in i.get("answerOption", []))
    assert all(
        o["valueCoding"]["system"] == "http://loinc.org" for i in items.values() for o in i.get("answerOption", [])
    )


def test_identity_is_stable_and_site_configured(replayed):
    sessions = list(replayed.values())
    first, again = (transaction_bundle(QUESTIONNAIRE, sessions, site=SITE) for _ in range(2))
    assert first == again  # re-export: same identifiers and fullUrls, so a server sees the same results
    stored = replayed["P-ES-0001"]
    response = entries(first, "QuestionnaireResponse")[[s.id for s in sessions].index(stored.id)]
    assert response["resource"]["identifier"] == {
        "system": "urn:barthel-kiosk:result",
        "value": f"hosp-north/ward3-bed2/{stored.id}",
    }
    assert (
        unquote(response["request"]["ifNoneExist"])
        == f"identifier=urn:barthel-kiosk:result|hosp-north/ward3-bed2/{stored.id}"
    )
    assert response["resource"]["subject"]["identifier"] == {
        "system": "https://hosp-north.example/sid/kiosk-patient",
        "value": "P-ES-0001",
    }
    assert response["resource"]["questionnaire"] == (
        f"https://hosp-north.example/fhir/Questionnaire/barthel-es|{questionnaire_version(QUESTIONNAIRE)}"
    )
    device = entries(first, "Device")[0]
    assert device["resource"]["identifier"] == [{"system": "urn:barthel-kiosk:hosp-north:kiosk", "value": "ward3-bed2"}]
    assert response["resource"]["author"]["reference"] == device["fullUrl"]
    other_kiosk = transaction_bundle(QUESTIONNAIRE, [stored], site=replace(SITE, kiosk_id="ward4-bed1"))
    assert (
        entries(other_kiosk, "QuestionnaireResponse")[0]["resource"]["identifier"]["value"]
        != response["resource"]["identifier"]["value"]
    )


def test_editing_the_questionnaire_file_changes_its_version(tmp_path):
    copy = tmp_path / "barthel.yaml"
    shutil.copy(ROOT / "kiosk/core/questionnaire/instruments/barthel.yaml", copy)
    assert questionnaire_version(load_questionnaire(copy)) == questionnaire_version(QUESTIONNAIRE)
    copy.write_text(copy.read_text(encoding="utf-8").replace("# Seconds.", "# Seconds (a comment)."), encoding="utf-8")
    assert questionnaire_version(load_questionnaire(copy)) == questionnaire_version(
        QUESTIONNAIRE
    )  # comments don't count
    copy.write_text(
        copy.read_text(encoding="utf-8").replace('en: "Unable"', 'en: "Cannot feed self"'), encoding="utf-8"
    )
    edited = questionnaire_version(load_questionnaire(copy))
    assert edited != questionnaire_version(QUESTIONNAIRE) and edited.startswith("1.0-")


def test_kiosk_validate_checks_answer_codes(tmp_path):
    copy = tmp_path / "barthel.yaml"
    text = (ROOT / "kiosk/core/questionnaire/instruments/barthel.yaml").read_text(encoding="utf-8")
    copy.write_text(
        text.replace('code: "LA31630-9"', 'code: "LA24937-7"').replace('code: "LA31644-0",', 'cod: "LA31644-0",'),
        encoding="utf-8",
    )
    problems = [p.message for p in check_questionnaire_file(copy)]
    assert any(
        "two options of items[0] have the answer code 'LA24937-7'" in m or ("answer code 'LA24937-7'" in m)
        for m in problems
    ), problems
    assert any("cod" in m for m in problems), problems
    assert all(str(p).startswith(f"{copy}:") for p in check_questionnaire_file(copy))


@pytest.mark.parametrize("bad", ["2026-13-40", "yesterday"])
def test_a_review_with_a_bad_time_is_a_clear_export_error(replayed, bad):
    from kiosk.export import ExportError

    with pytest.raises(ExportError, match="is not an ISO-8601 date and time"):
        fhir_response(QUESTIONNAIRE, replayed["TB-0001"], replace(signed(), signed_at=bad), SITE)


def test_a_correction_to_an_unknown_item_or_option_is_refused(replayed):
    from kiosk.export import ExportError

    with pytest.raises(ExportError, match="has no option 5"):
        fhir_response(QUESTIONNAIRE, replayed["TB-0001"], signed(ReviewState.AMENDED, fill("feeding", 5, 3)), SITE)
    with pytest.raises(ExportError, match="unknown item 'eating'"):
        fhir_response(QUESTIONNAIRE, replayed["TB-0001"], signed(ReviewState.AMENDED, fill("eating", 1)), SITE)


# fhir.resources does not check code bindings (a status outside R4's list): the schema does
@pytest.mark.parametrize(
    ("path", "bad", "models_reject"),
    [("status", "finished", False), ("authored", "23/11/2026", True), ("text", 42, True)],
)
def test_the_checkers_reject_what_r4_forbids(replayed, path, bad, models_reject):
    response = fhir_response(QUESTIONNAIRE, replayed["TB-0001"], site=SITE)
    check_fhir(response)
    if path == "text":
        response["item"][0]["text"] = bad
    else:
        response[path] = bad
    assert schema_errors(response)
    if models_reject:
        with pytest.raises(ValidationError):
            parse_r4(response)


def test_a_sign_off_that_still_changes_an_answer_is_reported_amended(replayed):
    stored = replayed["TB-0001"]  # feeding: option 3 at the kiosk
    review = signed(ReviewState.SIGNED_OFF, fill("feeding", 2, 3))
    response = fhir_response(QUESTIONNAIRE, stored, review, SITE)
    assert response["status"] == "amended" and total_answer(response) == [{"valueInteger": 95}]
    assert fhir_total(QUESTIONNAIRE, stored, review, SITE)["status"] == "amended"
    same = signed(ReviewState.SIGNED_OFF, fill("feeding", 3, 3))  # a "correction" to what was recorded
    assert fhir_response(QUESTIONNAIRE, stored, same, SITE)["status"] == "completed"


def test_a_session_of_another_questionnaire_is_never_exported_as_this_one(replayed):
    from kiosk.export import ExportError

    other = replace(replayed["TB-0001"], questionnaire_id="katz")
    with pytest.raises(ExportError, match="was answered on questionnaire 'katz', not on 'barthel'"):
        transaction_bundle(QUESTIONNAIRE, [replayed["TB-0002"], other], site=SITE)


def test_corrections_still_in_review_are_the_nurses_answers_not_the_kiosks(replayed):
    stored = replayed["TB-0001"]
    nurse = Correction("stairs", 2, 3, "saw the patient on the stairs", "nurse.kim", "2026-11-23T14:00:00Z")
    review = Review(ReviewState.UNREVIEWED, (nurse,))
    response = fhir_response(QUESTIONNAIRE, stored, review, SITE)
    check_fhir(response)
    assert response["status"] == "amended" and "extension" not in response  # changed, not signed off
    assert response["author"]["type"] == "Device"
    assert response["authored"] == "2026-11-23T14:00:00+00:00"
    assert fhir_total(QUESTIONNAIRE, stored, review, SITE)["status"] == "preliminary"


def test_a_questionnaire_in_one_language_has_no_empty_translations():
    english = replace(
        QUESTIONNAIRE,
        languages=("en",),
        title={"en": QUESTIONNAIRE.title["en"]},
        items=tuple(
            replace(
                item,
                text={"en": item.text["en"]},
                options=tuple(replace(o, label={"en": o.label["en"]}) for o in item.options),
            )
            for item in QUESTIONNAIRE.items
        ),
    )
    resource = fhir_questionnaire(english, "en", SITE)
    check_fhir(resource)
    assert "_text" not in json.dumps(resource) and "_display" not in json.dumps(resource)


def test_each_code_carries_loincs_display_once_and_the_kiosks_words_travel_beside_it(replayed):
    from kiosk.export import WORDING

    displays: dict[str, set[str]] = {}
    for language in ("en", "es", "fr"):
        questionnaire = fhir_questionnaire(QUESTIONNAIRE, language, SITE)
        for item in questionnaire["item"][:-1]:
            for option in item["answerOption"]:
                coding = option["valueCoding"]
                displays.setdefault(coding["code"], set()).add(coding["display"])
                assert "_display" not in coding  # LOINC's display is not translated into our wording
    assert all(len(shown) == 1 for shown in displays.values()), displays  # one code, one display, every language
    assert displays["LA12304-4"] == {"Dependent"} and displays["LA31643-2"] == {"Needs help with personal care"}
    spanish = fhir_questionnaire(QUESTIONNAIRE, "es", SITE)
    bathing = next(i for i in spanish["item"] if i["linkId"] == "bathing")
    words = {e["url"]: e for e in bathing["extension"]}[WORDING]
    assert {w["url"]: w["valueString"] for w in words["extension"]} == {
        "clinical": QUESTIONNAIRE.item("bathing").text["es"],
        "patient": QUESTIONNAIRE.item("bathing").patient["es"],
        "spoken": QUESTIONNAIRE.item("bathing").spoken["es"],
    }
    option = {e["url"]: e for e in bathing["answerOption"][0]["extension"]}[WORDING]
    assert {w["url"]: w["valueString"] for w in option["extension"]} == {
        "clinical": "Necesito ayuda",
        "patient": "Necesito ayuda",
    }
    response = fhir_response(QUESTIONNAIRE, replayed["P-ES-0001"], site=SITE)
    for item in response["item"][:-1]:
        said = {w["url"]: w["valueString"] for w in item["extension"][0]["extension"]}
        assert said["patient"] == QUESTIONNAIRE.item(item["linkId"]).patient_text_in("es")
        chosen = {w["url"]: w["valueString"] for w in item["answer"][0]["extension"][0]["extension"]}
        assert chosen["patient"] in [o.patient_label_in("es") for o in QUESTIONNAIRE.item(item["linkId"]).options]


def test_a_correction_is_a_provenance_naming_who_when_why_and_the_kiosks_answer(replayed):
    from kiosk.export import REPLACED_ANSWER

    stored = replayed["TB-0001"]  # feeding: option 3 (LA12302-8) at the kiosk
    nurse = Correction("feeding", 2, 3, "needs help cutting", "nurse.kim", "2026-11-23T14:00:00Z")
    doctor = Correction("feeding", 1, 2, "cannot feed at all", "dr.lopez", "2026-11-23T14:30:00Z")
    bundle = transaction_bundle(QUESTIONNAIRE, [stored], [signed(ReviewState.AMENDED, nurse, doctor)], SITE)
    check_fhir(bundle)
    response = entries(bundle, "QuestionnaireResponse")[0]
    first, second = (e["resource"] for e in entries(bundle, "Provenance"))
    assert first["recorded"] == "2026-11-23T14:00:00+00:00" and first["reason"] == [{"text": "needs help cutting"}]
    assert first["target"][0]["reference"] == response["fullUrl"]
    assert first["target"][0]["extension"][0]["valueUri"] == "feeding"
    assert next(i for i in response["resource"]["item"] if i["linkId"] == "feeding")["id"] == "feeding"
    assert first["agent"][0]["who"]["identifier"] == {"system": "urn:barthel-kiosk:station:staff", "value": "nurse.kim"}
    (kiosk_answer,) = first["entity"]
    assert kiosk_answer["extension"][0] == {
        "url": REPLACED_ANSWER,
        "valueCoding": {"system": "http://loinc.org", "code": "LA12302-8", "display": "Independent"},
    }
    assert kiosk_answer["agent"][0]["who"]["reference"] == entries(bundle, "Device")[0]["fullUrl"]
    assert "as recorded by the kiosk" in kiosk_answer["what"]["display"]
    (nurses_answer,) = second["entity"]  # the doctor's change replaced the nurse's answer, not the kiosk's
    assert nurses_answer["agent"][0]["who"]["identifier"]["value"] == "nurse.kim"
    assert nurses_answer["extension"][0]["valueCoding"]["code"] == "LA31630-9"
    again = transaction_bundle(QUESTIONNAIRE, [stored], [signed(ReviewState.AMENDED, nurse, doctor)], SITE)
    assert [e["request"] for e in entries(again, "Provenance")] == [e["request"] for e in entries(bundle, "Provenance")]
    assert all(
        e["request"]["method"] == "PUT" and e["request"]["url"].startswith("Provenance/")
        for e in entries(bundle, "Provenance")
    )


def test_one_review_state_from_the_trail_for_every_export():
    from types import SimpleNamespace

    from kiosk.core.review import review_from_steps, review_state

    def step(action, author="dr.lopez", item=None, option=None, previous=None, reason="", at="2026-11-23T15:00:00Z"):
        return SimpleNamespace(
            action=action, author=author, item_id=item, option=option, previous_option=previous, reason=reason, at=at
        )

    recorded = {"feeding": 3, "stairs": 3}
    assert review_state(review_from_steps([]), recorded) is ReviewState.UNREVIEWED
    corrected = [step("correct", "nurse.kim", "feeding", 2, 3, "help")]
    assert review_state(review_from_steps(corrected), recorded) is ReviewState.CORRECTED
    assert review_state(review_from_steps(corrected + [step("sign_off")]), recorded) is ReviewState.AMENDED
    back = corrected + [step("correct", "nurse.kim", "feeding", 3, 2, "misread"), step("sign_off")]
    assert review_state(review_from_steps(back), recorded) is ReviewState.SIGNED_OFF  # the kiosk's answer again
    reopened = [
        step("sign_off", at="2026-11-23T15:00:00Z"),
        step("amend", reason="new findings", at="2026-11-23T16:00:00Z"),
    ]
    review = review_from_steps(reopened)
    assert not review.final and review_state(review, recorded) is ReviewState.CORRECTED
    (reopening,) = review.reopenings
    assert (reopening.reason, reopening.signed_by, reopening.signed_at) == (
        "new findings",
        "dr.lopez",
        "2026-11-23T15:00:00Z",
    )
    again = review_from_steps(
        reopened
        + [
            step("correct", item="stairs", option=2, previous=3, reason="lift"),
            step("sign_off", at="2026-11-23T17:00:00Z"),
        ]
    )
    assert again.final and again.signed_at == "2026-11-23T17:00:00Z"
    assert review_state(again, recorded) is ReviewState.AMENDED


def test_kiosk_validate_refuses_one_code_with_two_displays(tmp_path):
    copy = tmp_path / "barthel.yaml"
    text = (ROOT / "kiosk/core/questionnaire/instruments/barthel.yaml").read_text(encoding="utf-8")
    copy.write_text(
        text.replace('code: "LA12304-4", display: "Dependent"', 'code: "LA12304-4", display: "I need help"', 1),
        encoding="utf-8",
    )
    problems = [str(p) for p in check_questionnaire_file(copy)]
    assert problems and all(p.startswith(f"{copy}:") for p in problems)
    assert any(
        "code 'LA12304-4' has the display 'Dependent' here but 'I need help' at items[1].options[0].code: "
        "one code, one display" in p
        for p in problems
    ), problems
    assert check_questionnaire_file(ROOT / "kiosk/core/questionnaire/instruments/barthel.yaml") == []
