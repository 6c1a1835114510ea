"""A patient's course as a server-rendered SVG step plot per instrument: the total of each signed
or waiting visit over calendar time, with the questionnaire's bands shaded behind. The y axis spans
the instrument's own total range (:attr:`Questionnaire.total_range`: 0-15, 0-8, -10-30...), so each
instrument plots on its own scale.

A band is coloured by what it says about the patient, as the instrument declares it (a band's
``concern``: none, low, moderate, high), never by its place in the list: before, the first band
was red, so a normal GDS-15 and a fully independent Lawton sat on red. A band that declares
nothing (the Lawton's "no cut-off", or a file that does not say) is grey. A legend under the
plot names each band in words with its range and colour.

Steps, not lines: a total holds until the next visit measures it again, and a line between visits
would invent values nobody measured. Incomplete visits have no total and are not drawn; a visit
whose result is not yet signed off is drawn hollow. Everything is escaped.
"""

from __future__ import annotations

from datetime import datetime
from html import escape

from kiosk.core.questionnaire import Band, Questionnaire
from station.results import Result

WIDTH, HEIGHT = 480, 220
LEFT, RIGHT, TOP, BOTTOM = 44, 16, 12, 34
#: a band's fill by its declared concern (None: declared nothing)
CONCERN_FILLS = {
    "none": "#dff0e6",
    "low": "#fff7d6",
    "moderate": "#ffe6c7",
    "high": "#fde2e0",
    None: "#eef0f3",
}
#: the legend's words for each concern
CONCERN_WORDS = {
    "none": "no concern",
    "low": "low concern",
    "moderate": "moderate concern",
    "high": "high concern",
    None: "not graded by the instrument",
}


def _when(result: Result) -> datetime:
    return datetime.fromisoformat((result.finished_at or result.started_at).replace("Z", "+00:00"))


def course_svg(q: Questionnaire, results: list[Result]) -> str:
    """The plot of ``results`` for questionnaire ``q`` as an inline ``<svg>`` (a note when no visit
    has a total yet)."""
    name = q.title.get("en") or q.id
    points = [(r, _when(r)) for r in results if r.questionnaire_id == q.id and r.total is not None]
    if not points:
        return f'<p class="muted">No complete {escape(name)} total yet.</p>'
    low, high = q.total_range
    low = min([low] + [r.total or 0 for r, _ in points])
    high = max([high] + [r.total or 0 for r, _ in points])
    if high == low:
        high = low + 1
    first, last = points[0][1], points[-1][1]
    span = max((last - first).total_seconds(), 1.0)
    t_end = span * 1.08 if len(points) > 1 else 1.0
    plot_w, plot_h = WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM

    def x(when: datetime) -> float:
        return LEFT + plot_w * ((when - first).total_seconds() / t_end if len(points) > 1 else 0.5)

    def y(total: float) -> float:
        return TOP + plot_h * (high - total) / (high - low)

    parts = [
        f'<svg class="course-plot" viewBox="0 0 {WIDTH} {HEIGHT}" role="img" '
        f'aria-label="{escape(name)} totals over time" xmlns="http://www.w3.org/2000/svg">'
    ]
    bands = q.bands_named(None).bands
    for band in bands:
        if band.max < low or band.min > high:
            continue
        y1, y2 = y(min(band.max + 0.5, high)), y(max(band.min - 0.5, low))
        parts.append(
            f'<rect x="{LEFT}" y="{max(TOP, y1):.1f}" width="{plot_w}" '
            f'height="{max(0.0, min(TOP + plot_h, y2) - max(TOP, y1)):.1f}" '
            f'fill="{CONCERN_FILLS[band.concern]}" class="band band-{band.concern or "undeclared"}">'
            f"<title>{escape(_band_words(band))}</title></rect>"
        )
    for tick in sorted({low, (low + high) // 2, high}):
        parts.append(f'<text x="{LEFT - 6}" y="{y(tick) + 4:.1f}" text-anchor="end">{tick}</text>')
    steps: list[str] = []
    for index, (result, when) in enumerate(points):
        if index:
            steps.append(f"{x(when):.1f},{y(points[index - 1][0].total or 0):.1f}")
        steps.append(f"{x(when):.1f},{y(result.total or 0):.1f}")
    steps.append(f"{LEFT + plot_w:.1f},{y(points[-1][0].total or 0):.1f}" if len(points) > 1 else "")
    parts.append(f'<polyline fill="none" stroke="#1b6ac9" stroke-width="2" points="{" ".join(steps).strip()}"/>')
    for result, when in points:
        final = result.review in ("signed_off", "amended")
        label = escape(
            f"{when:%Y-%m-%d}: {result.total}/{result.max_total}"
            f"{' ' + result.band if result.band else ''}, {result.review_words}"
        )
        parts.append(
            f'<circle cx="{x(when):.1f}" cy="{y(result.total or 0):.1f}" r="5" '
            f'fill="{"#1b6ac9" if final else "#fff"}" stroke="#1b6ac9" stroke-width="2" '
            f'class="visit-point"><title>{label}</title></circle>'
        )
    parts.append(f'<text x="{LEFT}" y="{HEIGHT - 10}">{first:%Y-%m-%d}</text>')
    if len(points) > 1:
        parts.append(f'<text x="{LEFT + plot_w}" y="{HEIGHT - 10}" text-anchor="end">{last:%Y-%m-%d}</text>')
    parts.append("</svg>")
    return "".join(parts) + _legend(bands)


def _band_words(band: Band) -> str:
    return f"{band.label.get('en') or band.id} ({band.min}-{band.max})"


def _legend(bands: tuple[Band, ...]) -> str:
    """Each band in words, its range, and its colour with what the colour means."""
    rows = "".join(
        f'<li><span class="swatch" style="background:{CONCERN_FILLS[b.concern]}"></span>'
        f"{escape(_band_words(b))}: {escape(CONCERN_WORDS[b.concern])}</li>"
        for b in bands
    )
    return f'<ul class="band-legend">{rows}</ul>'
