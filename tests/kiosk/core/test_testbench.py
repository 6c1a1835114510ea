"""Test-bench equivalence: the six scripted patients of the CLARC paper's Table 2, replayed through
the real session core, give exactly the committed test-bench context traces (and so their metrics)."""

from __future__ import annotations

from pathlib import Path

import pytest

from kiosk.commands.replay import load_script, run_script
from qos import load_trace, replay

ROOT = Path(__file__).resolve().parents[3]


@pytest.mark.parametrize("n", range(1, 7))
def test_replayed_patient_gives_the_test_bench_trace_event_by_event(n):
    result = run_script(load_script(ROOT / f"recordings/patients/barthel{n}.yaml"))
    expected = load_trace(ROOT / f"recordings/testbench/barthel{n}.yaml")
    got = [e.to_dict() for e in result.trace.events]
    want = [e.to_dict() for e in expected.events]
    for index, (g, w) in enumerate(zip(got, want)):
        assert g == w, f"barthel{n} event {index}: replay {g} != test-bench {w}"
    assert len(got) == len(want)
    assert result.qos == replay(expected)


def test_the_test_bench_patients_exercise_every_incident_kind():
    kinds = {
        step.kind
        for n in range(1, 7)
        for q in load_script(ROOT / f"recordings/patients/barthel{n}.yaml").questions
        for step in q.steps
    }
    assert {"answer", "pause", "resume", "call_doctor", "continue", "person_lost", "person_back"} <= kinds
