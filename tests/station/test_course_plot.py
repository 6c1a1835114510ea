"""The patient's course plot: a step per instrument over calendar time (a total holds until the
next visit measures it), only complete totals drawn, a result not yet signed off drawn hollow."""

from __future__ import annotations

import re

from kiosk.core.questionnaire import load_questionnaire
from station.course_plot import course_svg
from station.results import Result


def visit(day: int, total: int | None, review: str = "signed_off") -> Result:
    return Result(
        f"s{day}",
        "bed1",
        "NHC-1",
        "barthel",
        f"2026-0{day}-01T10:00:00+00:00",
        f"2026-0{day}-01T10:20:00+00:00",
        "finished",
        total,
        100,
        total is not None,
        "moderate" if total else None,
        review,
        False,
        "order",
        None,
    )


def test_totals_are_steps_and_unsigned_results_hollow():
    svg = course_svg(load_questionnaire(), [visit(1, 60), visit(3, None), visit(7, 85, "unreviewed")])
    (points,) = re.findall(r'<polyline [^>]*points="([^"]+)"', svg)
    xy = [tuple(map(float, p.split(","))) for p in points.split()]
    # first visit, then the same total held until the second (same y), then the jump (same x)
    assert xy[0][1] == xy[1][1] and xy[1][0] == xy[2][0] and xy[2][1] < xy[1][1]
    circles = re.findall(r'<circle [^>]*fill="([^"]+)"', svg)
    assert circles == ["#1b6ac9", "#fff"]  # the incomplete visit has no point; the unreviewed one is hollow
    assert "2026-01-01: 60/100 moderate, signed off" in svg and "85/100 moderate, unreviewed" in svg


def test_a_patient_without_a_complete_total_gets_a_sentence():
    assert course_svg(load_questionnaire(), [visit(1, None)]) == '<p class="muted">No complete barthel total yet.</p>'
