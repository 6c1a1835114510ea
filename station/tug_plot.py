"""A patient's Timed Up and Go times over calendar time, as a server-rendered SVG: one point per
time taken (filled: the camera's, hollow: a stopwatch's), and the site's threshold as a dashed
line labelled "site's threshold" (the latest test's), never a diagnosis. Points, not a line: a
time holds for the day it was taken, and a line between tests would invent times nobody
measured. Rejected tests have no time and are not drawn. Everything is escaped.
"""

from __future__ import annotations

from collections.abc import Sequence
from datetime import datetime
from html import escape

from station.tugs import StationTug

WIDTH, HEIGHT = 480, 220
LEFT, RIGHT, TOP, BOTTOM = 44, 16, 12, 34


def _when(tug: StationTug) -> datetime:
    return datetime.fromisoformat(tug.at.replace("Z", "+00:00"))


def tug_svg(found: Sequence[StationTug]) -> str:
    """The plot of the timed results of ``found`` (oldest first), or a note when none has a time."""
    points = [(t, _when(t), t.total_s) for t in found if t.total_s is not None]
    if not points:
        return '<p class="muted">No Timed Up and Go time yet.</p>'
    threshold = points[-1][0].threshold_s
    high = max([threshold * 1.5] + [s for _, _, s in points]) * 1.05
    first, last = points[0][1], points[-1][1]
    span = max((last - first).total_seconds(), 1.0)
    plot_w, plot_h = WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM

    def x(when: datetime) -> float:
        return LEFT + plot_w * (0.04 + 0.92 * (when - first).total_seconds() / span if len(points) > 1 else 0.5)

    def y(seconds: float) -> float:
        return TOP + plot_h * (high - seconds) / high

    parts = [
        f'<svg class="course-plot tug-plot" viewBox="0 0 {WIDTH} {HEIGHT}" role="img" '
        'aria-label="Timed Up and Go times over time" xmlns="http://www.w3.org/2000/svg">',
        f'<line x1="{LEFT}" x2="{LEFT + plot_w}" y1="{y(threshold):.1f}" y2="{y(threshold):.1f}" '
        f'stroke="#b3261e" stroke-dasharray="6 4" class="tug-threshold"/>',
        f'<text x="{LEFT + plot_w}" y="{y(threshold) - 4:.1f}" text-anchor="end">'
        f"site&#39;s threshold {threshold:g} s</text>",
    ]
    for tick in (0, round(high / 2), round(high)):
        parts.append(f'<text x="{LEFT - 6}" y="{y(tick) + 4:.1f}" text-anchor="end">{tick} s</text>')
    for tug, when, seconds in points:
        side = "above" if seconds > tug.threshold_s else "not above"
        label = escape(f"{when:%Y-%m-%d}: {seconds:.1f} s, {side} the site's threshold ({tug.method})")
        fill = "#1b6ac9" if tug.method == "camera" else "#fff"
        parts.append(
            f'<circle cx="{x(when):.1f}" cy="{y(seconds):.1f}" r="5" fill="{fill}" stroke="#1b6ac9" '
            f'stroke-width="2" class="tug-point"><title>{label}</title></circle>'
        )
    parts.append(f'<text x="{LEFT}" y="{HEIGHT - 10}">{first:%Y-%m-%d}</text>')
    if len(points) > 1:
        parts.append(f'<text x="{LEFT + plot_w}" y="{HEIGHT - 10}" text-anchor="end">{last:%Y-%m-%d}</text>')
    parts.append("</svg>")
    return "".join(parts)
