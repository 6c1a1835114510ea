"""A Timed Up and Go time out: a valid R4 Observation (LOINC 89423-8 in s, camera or stopwatch as
its method, the kiosk as device for the camera, the phases as components) and CSV rows."""

from __future__ import annotations

from dataclasses import replace

import pytest

from kiosk.core.site import ExportSite
from kiosk.core.tug import analyse
from kiosk.core.tug.families import generate
from kiosk.export.tug import TugTime, fhir_tug, phases_total, tug_csv_rows
from tests.kiosk.export.standard import check_fhir

SITE = ExportSite(site="ward3", kiosk_id="bed2")


def camera_time(accepted_by: str = "nurse.lee") -> TugTime:
    sequence, truth = generate("normal", 31)
    result = analyse(replace(sequence, go_t=truth.onset_t - 0.5))  # the kiosk's Go, as a camera test has
    assert result.valid and result.total_s is not None
    return TugTime(
        result_id="s-1",
        patient_id="P-0042",
        total_s=result.total_s,
        method="camera",
        effective="2026-11-28T04:50:00+00:00",
        phases=result.phases,
        accepted_by=accepted_by,
    )


def test_a_camera_time_is_a_valid_observation_with_its_phases():
    time = camera_time()
    observation = fhir_tug(time, SITE)
    check_fhir(observation)
    assert observation["code"]["coding"][0]["code"] == "89423-8"
    assert observation["valueQuantity"] == {
        "value": round(time.total_s, 2),
        "unit": "s",
        "system": "http://unitsofmeasure.org",
        "code": "s",
    }
    assert observation["method"]["coding"][0]["code"] == "camera"
    assert observation["device"]["identifier"]["value"] == "bed2"
    assert observation["status"] == "final" and observation["performer"][0]["display"] == "nurse.lee"
    names = [c["code"]["coding"][0]["code"] for c in observation["component"]]
    assert names == ["sit_to_stand", "walk_out", "turn", "walk_back", "turn_and_sit"]
    assert observation["identifier"][0]["value"] == "ward3/bed2/s-1/tug"


def test_a_stopwatch_time_names_no_device_and_has_no_phases():
    time = TugTime(
        result_id="s-2", patient_id="P-7", total_s=14.2, method="stopwatch", effective="2026-11-28T05:00:00Z"
    )
    observation = fhir_tug(time, SITE)
    check_fhir(observation)
    assert "device" not in observation and "component" not in observation
    assert observation["status"] == "preliminary"


def test_an_unknown_method_is_refused():
    with pytest.raises(ValueError, match="method 'guess'"):
        fhir_tug(TugTime(result_id="x", patient_id="p", total_s=9.0, method="guess", effective="2026-11-28T05:00:00Z"))


def test_csv_rows_have_the_total_then_each_phase():
    time = camera_time(accepted_by="")
    rows = tug_csv_rows(time)
    assert rows[0][4:6] == ("total", f"{time.total_s:.2f}")
    assert [r[4] for r in rows[1:]] == ["sit_to_stand", "walk_out", "turn", "walk_back", "turn_and_sit"]
    assert phases_total(time.phases) == pytest.approx(time.phases[-1].end_t - time.phases[0].start_t)
