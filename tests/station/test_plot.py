"""The session page's QoS plot: metrics drawn as steps (a value holds until the next sample) with
the session's incidents marked, from a real session's stored samples."""

from __future__ import annotations

import re

from station.plot import qos_svg
from station.sessions import Row as InboxRow, fold
from tests.station.helpers import PATIENTS, record_patient


def _session(script: str):
    rows = record_patient(PATIENTS / script)
    return fold(rows[0].session_id, [InboxRow(r.seq, r.kind, r.payload, r.at) for r in rows])


def test_each_metric_is_a_step_function_of_its_samples():
    stored = _session("barthel5.yaml")
    svg = qos_svg(stored)
    lines = re.findall(r'<polyline[^>]*points="([^"]+)"><title>([^<]+)</title>', svg)
    assert {name for _, name in lines} == {n for s in stored.metrics for n in s.metrics}
    for points, name in lines:
        xy = [tuple(map(float, p.split(","))) for p in points.split()]
        samples = [s for s in stored.metrics if name in s.metrics]
        assert len(xy) == 2 * len(samples)  # a rise or fall at each sample, a run after it
        for (x0, y0), (x1, y1) in zip(xy, xy[1:]):
            assert x0 == x1 or y0 == y1  # only horizontal runs and vertical jumps, never slopes


def test_incidents_are_marked_with_what_happened():
    stored = _session("barthel5.yaml")
    svg = qos_svg(stored)
    marks = re.findall(r'class="incident incident-([a-z_]+)"><title>([^<]+)</title>', svg)
    logged = [e.kind for e in stored.log if e.kind in ("pause", "call_doctor", "person_lost", "attempt_timed_out")]
    assert logged and [kind for kind, _ in marks if kind in logged] == logged
    assert all(" s" in title for _, title in marks)


def test_a_session_without_samples_says_so_instead_of_an_empty_plot():
    stored = _session("barthel1.yaml")
    empty = type(stored)(**{**stored.__dict__, "metrics": ()})
    assert "No QoS samples" in qos_svg(empty)
