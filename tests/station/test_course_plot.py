"""The patient's course plot: a step per instrument over calendar time (a total holds until the
next visit measures it), only complete totals drawn, a result not yet signed off drawn hollow."""

from __future__ import annotations

import re
from dataclasses import replace

from kiosk.core.questionnaire import bundled_path, load_questionnaire
from station.course_plot import course_svg
from station.results import Result
from tests.instruments import MOOD4


def visit(
    day: int, total: int | None, review: str = "signed_off", instrument: str = "barthel", top: int = 100
) -> Result:
    return Result(
        f"s{day}",
        "bed1",
        "NHC-1",
        instrument,
        f"2026-0{day}-01T10:00:00+00:00",
        f"2026-0{day}-01T10:20:00+00:00",
        "finished",
        total,
        top,
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
    assert (
        course_svg(load_questionnaire(), [visit(1, None)])
        == '<p class="muted">No complete Barthel Index total yet.</p>'
    )


def _ticks(svg: str) -> list[str]:
    return re.findall(r'<text x="\d+" y="[\d.]+" text-anchor="end">(-?\d+)</text>', svg)


def _ys(svg: str) -> list[float]:
    return [float(v) for v in re.findall(r'<circle cx="[\d.]+" cy="([\d.]+)"', svg)]


def test_each_instrument_plots_on_its_own_scale():
    barthel = course_svg(load_questionnaire(), [visit(1, 20)])
    mood = load_questionnaire(MOOD4)
    own = course_svg(mood, [visit(1, 20, instrument="mood4", top=25)])
    assert _ticks(barthel) == ["0", "50", "100"] and _ticks(own) == ["0", "12", "25"]
    # 20 of 100 sits low on the Barthel's axis, 20 of 25 high on the mood scale's
    assert _ys(own)[0] < _ys(barthel)[0]
    assert 'aria-label="Mood check (4 items) totals over time"' in own and "20/25" in own
    # both of its bands are shaded, named in words, and nothing is drawn outside the plot
    assert re.findall(r"<title>([^<]+)</title></rect>", own) == [
        "No depression suggested (0-10)",
        "Suggests depression (15-25)",
    ]


def test_a_scale_with_negative_totals_keeps_its_points_inside_the_plot():
    """An instrument whose options subtract points (totals -8 to 4 here) has an axis from its
    lowest to its highest total, not from 0."""
    mood = load_questionnaire(MOOD4)
    negative = replace(
        mood,
        items=tuple(
            replace(item, options=tuple(replace(o, points=o.points - 2) for o in item.options)) for item in mood.items
        ),
    )
    assert negative.total_range == (-8, 17)
    svg = course_svg(negative, [visit(1, -8, instrument="mood4"), visit(2, 17, instrument="mood4")])
    assert _ticks(svg) == ["-8", "4", "17"]
    low, high = _ys(svg)
    assert high < low and 12 <= high and low <= 12 + 220 - 12 - 34


def _band_under(svg: str, y: float) -> str:
    """The class of the band drawn at height ``y`` (the one whose rectangle spans it)."""
    for top, height, css in re.findall(
        r'<rect x="\d+" y="([\d.]+)" width="\d+" height="([\d.]+)" fill="[^"]+" class="([^"]+)"', svg
    ):
        if float(top) <= y <= float(top) + float(height):
            return css
    raise AssertionError(f"no band at y={y}")


def test_bands_are_coloured_by_what_they_mean_not_by_their_place():
    """Before, the first band was red: a normal GDS-15 and a fully independent Lawton sat on red."""
    gds = load_questionnaire(bundled_path("gds15.yaml"))
    normal = course_svg(gds, [visit(1, 2, instrument="gds15", top=15)])
    assert _band_under(normal, _ys(normal)[0]) == "band band-none"  # the first band, and green
    assert 'fill="#dff0e6" class="band band-none"' in normal
    depressed = course_svg(gds, [visit(1, 12, instrument="gds15", top=15)])
    assert _band_under(depressed, _ys(depressed)[0]) == "band band-high"
    lawton = load_questionnaire(bundled_path("lawton.yaml"))
    independent = course_svg(lawton, [visit(1, 8, instrument="lawton", top=8)])
    # the Lawton has no cut-off: its one band judges nothing, and is grey
    assert _band_under(independent, _ys(independent)[0]) == "band band-undeclared"
    barthel = course_svg(load_questionnaire(), [visit(1, 100)])
    assert _band_under(barthel, _ys(barthel)[0]) == "band band-none"


def test_a_legend_names_each_band_its_range_and_what_its_colour_means():
    svg = course_svg(load_questionnaire(bundled_path("gds15.yaml")), [visit(1, 2, instrument="gds15", top=15)])
    legend = re.findall(r'<li><span class="swatch" style="background:([^"]+)"></span>([^<]+)</li>', svg)
    assert legend == [("#dff0e6", "Normal (0-5): no concern"), ("#fde2e0", "Suggests depression (6-15): high concern")]
    undeclared = course_svg(load_questionnaire(MOOD4), [visit(1, 20, instrument="mood4", top=25)])
    assert "No depression suggested (0-10): not graded by the instrument" in undeclared


def test_a_band_concern_is_checked_and_kept_in_the_captured_definition(tmp_path):
    from kiosk.core.questionnaire import QuestionnaireError
    from kiosk.core.questionnaire.definition import DefinitionError, canonical, questionnaire_from

    gds = load_questionnaire(bundled_path("gds15.yaml"))
    again = questionnaire_from(canonical(gds))
    assert [b.concern for b in again.bands_named(None).bands] == ["none", "high"]
    captured = canonical(gds)
    captured["band_sets"][0]["bands"][0]["concern"] = "alarming"
    try:
        questionnaire_from(captured)
    except DefinitionError as exc:
        assert "concern must be one of none, low, moderate, high" in str(exc)
    else:
        raise AssertionError("an unknown concern was taken")
    text = bundled_path("gds15.yaml").read_text(encoding="utf-8").replace("concern: none", "concern: fine", 1)
    (tmp_path / "gds.yaml").write_text(text, encoding="utf-8")
    try:
        load_questionnaire(tmp_path / "gds.yaml")
    except QuestionnaireError as exc:
        assert "concern" in str(exc) and "fine" in str(exc), exc
    else:
        raise AssertionError("an unknown concern in a file was taken")
