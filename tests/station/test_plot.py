"""The session page's QoS plot: metrics drawn as steps (a value holds until the next sample) with
the session's incidents marked, from a real session's stored samples."""

from __future__ import annotations

import re

from station.plot import qos_svg
from station.sessions import Row as InboxRow
from station.sessions import fold
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
        for (x0, y0), (x1, y1) in zip(xy, xy[1:], strict=False):
            assert x0 == x1 or y0 == y1  # only horizontal runs and vertical jumps, never slopes


def test_incidents_are_marked_with_what_happened():
    stored = _session("barthel5.yaml")
    svg = qos_svg(stored)
    marks = re.findall(r'class="incident incident-([a-z_]+)"><title>([^<]+)</title>', svg)
    logged = [e.kind for e in stored.log if e.kind in ("pause", "doctor_called", "person_lost", "attempt_timed_out")]
    assert logged and [kind for kind, _ in marks if kind in logged] == logged
    assert all(" s" in title for _, title in marks)


def test_a_session_without_samples_says_so_instead_of_an_empty_plot():
    stored = _session("barthel1.yaml")
    empty = type(stored)(**{**stored.__dict__, "metrics": ()})
    assert "No QoS samples" in qos_svg(empty)


def test_adaptations_are_marked_and_metrics_have_the_kiosks_colours():
    """The station's plot marks each adaptation switching on or off, as the kiosk's plot does, and
    draws each metric in the colour the kiosk draws it in (one palette, kiosk.export.qos_plot)."""
    from kiosk.export.qos_plot import METRIC_COLOURS
    from kiosk.store.records import AdaptationRecord

    stored = _session("barthel5.yaml")
    adapted = type(stored)(
        **{
            **stored.__dict__,
            "adaptations": (
                AdaptationRecord(12.0, "longer_attempts", True, "Interaction 0.2 < 0.3"),
                AdaptationRecord(30.0, "voice_off", True, "VoiceInteractionQuality 0.1 < 0.2"),
            ),
        }
    )
    svg = qos_svg(adapted)
    titles = re.findall(r'class="adaptation"[^>]*><title>([^<]+)</title>', svg)
    assert titles == ["longer attempts on at 12 s", "voice answers off on at 30 s"]
    for colour, name in re.findall(r'<polyline fill="none" stroke="([^"]+)"[^>]*><title>([^<]+)</title>', svg):
        if name in METRIC_COLOURS:
            assert colour == METRIC_COLOURS[name], name
    assert "adaptation" in svg.split('class="incident-key">', 1)[1]
