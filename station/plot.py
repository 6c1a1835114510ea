"""The session's QoS metrics as a server-rendered SVG step plot, with its incidents and the
kiosk's adaptations marked.

A metric keeps its value until the next update, so each series is drawn as steps (a horizontal
run, then a vertical jump), never as lines between samples, which would invent values the engine
never published. Incidents (pause, doctor call, patient away, a question timing out, ...) and
adaptations switching on or off (slow speech, voice answers off, longer attempts) are vertical
marks with their words in a tooltip and a legend; everything is escaped. The colours and words
are the kiosk's own (:mod:`kiosk.export.qos_plot`): a metric looks the same on both.
"""

from __future__ import annotations

from html import escape

from kiosk.export.qos_plot import INCIDENT_WORDS, MARK_COLOURS, metric_colour, plot_marks
from kiosk.store.database import StoredSession

WIDTH, HEIGHT = 760, 298
LEFT, RIGHT, TOP, BOTTOM = 44, 12, 14, 64
#: session-log kinds shown as incidents, with the words a clinician reads
INCIDENTS = INCIDENT_WORDS


def _fmt(value: float) -> str:
    return f"{value:.1f}"


def qos_svg(stored: StoredSession) -> str:
    """The plot as an inline ``<svg>`` element (a short note when there are no samples)."""
    samples = stored.metrics
    if not samples:
        return '<p class="muted">No QoS samples were recorded for this session.</p>'
    names = sorted({name for s in samples for name in s.metrics})
    incidents = [e for e in stored.log if e.kind in INCIDENTS]
    adaptations = [m for m in plot_marks(stored, ()) if m.kind == "adaptation"]
    t_end = max([s.t for s in samples] + [e.t for e in incidents] + [m.t for m in adaptations]) or 1.0
    t_end *= 1.02
    values = [float(v) for s in samples for v in s.metrics.values()]
    low, high = min(0.0, *values), max(1.0, *values)
    plot_w, plot_h = WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM

    def x(t: float) -> float:
        return LEFT + plot_w * t / t_end

    def y(v: float) -> float:
        return TOP + plot_h * (high - v) / ((high - low) or 1.0)

    parts = [
        f'<svg class="qos-plot" viewBox="0 0 {WIDTH} {HEIGHT}" role="img" '
        f'aria-label="QoS metrics over the session, with incidents" xmlns="http://www.w3.org/2000/svg">'
    ]
    for tick in (low, (low + high) / 2, high):
        parts.append(f'<line x1="{LEFT}" x2="{WIDTH - RIGHT}" y1="{_fmt(y(tick))}" y2="{_fmt(y(tick))}" class="grid"/>')
        parts.append(f'<text x="{LEFT - 6}" y="{_fmt(y(tick) + 4)}" text-anchor="end">{tick:g}</text>')
    for t_tick in range(0, int(t_end) + 1, max(60, int(t_end / 6) // 60 * 60 or 60)):
        parts.append(
            f'<text x="{_fmt(x(t_tick))}" y="{HEIGHT - BOTTOM + 16}" text-anchor="middle">'
            f"{t_tick // 60}:{t_tick % 60:02d}</text>"
        )
    for incident in incidents:
        label = escape(f"{INCIDENTS[incident.kind]} at {incident.t:.0f} s {incident.detail}".strip())
        parts.append(
            f'<line x1="{_fmt(x(incident.t))}" x2="{_fmt(x(incident.t))}" y1="{TOP}" '
            f'y2="{TOP + plot_h}" style="stroke: {MARK_COLOURS["incident"]}" '
            f'class="incident incident-{escape(incident.kind)}">'
            f"<title>{label}</title></line>"
        )
    for mark in adaptations:
        label = escape(f"{mark.label} at {mark.t:.0f} s")
        parts.append(
            f'<line x1="{_fmt(x(mark.t))}" x2="{_fmt(x(mark.t))}" y1="{TOP}" y2="{TOP + plot_h}" '
            f'class="adaptation" style="stroke: {MARK_COLOURS["adaptation"]}" stroke-dasharray="4 3">'
            f"<title>{label}</title></line>"
        )
    for index, name in enumerate(names):
        points, last = [], None
        for sample in samples:
            if name not in sample.metrics:
                continue
            value = float(sample.metrics[name])
            if last is not None:
                points.append(f"{_fmt(x(sample.t))},{_fmt(y(last))}")
            points.append(f"{_fmt(x(sample.t))},{_fmt(y(value))}")
            last = value
        if last is not None:
            points.append(f"{_fmt(x(t_end))},{_fmt(y(last))}")
        colour = metric_colour(name, index)
        parts.append(
            f'<polyline fill="none" stroke="{colour}" stroke-width="2" points="{" ".join(points)}">'
            f"<title>{escape(name)}</title></polyline>"
        )
        parts.append(f'<text x="{LEFT + index * 200}" y="{HEIGHT - 26}" fill="{colour}">■ {escape(name)}</text>')
    keys = ([f'<tspan fill="{MARK_COLOURS["incident"]}">┆ incident</tspan>'] if incidents else []) + (
        [f'<tspan fill="{MARK_COLOURS["adaptation"]}">┆ adaptation</tspan>'] if adaptations else []
    )
    if keys:
        parts.append(
            f'<text x="{LEFT}" y="{HEIGHT - 8}" class="incident-key">{"  ".join(keys)}  (hover a line for what)</text>'
        )
    parts.append("</svg>")
    return "".join(parts)
