"""The session's QoS metrics as a server-rendered SVG step plot, with its incidents marked.

A metric keeps its value until the next update, so each series is drawn as steps (a horizontal
run, then a vertical jump), never as lines between samples, which would invent values the engine
never published. Incidents (pause, doctor call, patient away, a question timing out, ...) are
vertical marks with their name in a tooltip and a legend; everything is escaped.
"""

from __future__ import annotations

from html import escape

from kiosk.storage import StoredSession

WIDTH, HEIGHT = 760, 280
LEFT, RIGHT, TOP, BOTTOM = 44, 12, 14, 46
COLOURS = ("#1b6ac9", "#c2410c", "#15803d", "#7e22ce", "#a16207")
#: session-log kinds shown as incidents, with the words a clinician reads
INCIDENTS = {
    "pause": "paused", "resume": "resumed", "call_doctor": "doctor called", "doctor_called": "doctor called",
    "clinician_continue": "continued by staff", "doctor_continued": "continued by staff",
    "person_lost": "patient left", "person_back": "patient back", "attempt_timed_out": "no answer in time",
    "repeat": "asked to repeat", "abandoned": "abandoned",
}


def _fmt(value: float) -> str:
    return f"{value:.1f}"


def qos_svg(stored: StoredSession) -> str:
    """The plot as an inline ``<svg>`` element (a short note when there are no samples)."""
    samples = stored.metrics
    if not samples:
        return '<p class="muted">No QoS samples were recorded for this session.</p>'
    names = sorted({name for s in samples for name in s.metrics})
    incidents = [e for e in stored.log if e.kind in INCIDENTS]
    t_end = max([s.t for s in samples] + [e.t for e in incidents]) or 1.0
    t_end *= 1.02
    values = [float(v) for s in samples for v in s.metrics.values()]
    low, high = min(0.0, *values), max(1.0, *values)
    plot_w, plot_h = WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM

    def x(t: float) -> float:
        return LEFT + plot_w * t / t_end

    def y(v: float) -> float:
        return TOP + plot_h * (high - v) / ((high - low) or 1.0)

    parts = [f'<svg class="qos-plot" viewBox="0 0 {WIDTH} {HEIGHT}" role="img" '
             f'aria-label="QoS metrics over the session, with incidents" xmlns="http://www.w3.org/2000/svg">']
    for tick in (low, (low + high) / 2, high):
        parts.append(f'<line x1="{LEFT}" x2="{WIDTH - RIGHT}" y1="{_fmt(y(tick))}" y2="{_fmt(y(tick))}" '
                     'class="grid"/>')
        parts.append(f'<text x="{LEFT - 6}" y="{_fmt(y(tick) + 4)}" text-anchor="end">{tick:g}</text>')
    for t_tick in range(0, int(t_end) + 1, max(60, int(t_end / 6) // 60 * 60 or 60)):
        parts.append(f'<text x="{_fmt(x(t_tick))}" y="{HEIGHT - BOTTOM + 16}" text-anchor="middle">'
                     f'{t_tick // 60}:{t_tick % 60:02d}</text>')
    for incident in incidents:
        label = escape(f"{INCIDENTS[incident.kind]} at {incident.t:.0f} s {incident.detail}".strip())
        parts.append(f'<line x1="{_fmt(x(incident.t))}" x2="{_fmt(x(incident.t))}" y1="{TOP}" '
                     f'y2="{TOP + plot_h}" class="incident incident-{escape(incident.kind)}">'
                     f'<title>{label}</title></line>')
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
        colour = COLOURS[index % len(COLOURS)]
        parts.append(f'<polyline fill="none" stroke="{colour}" stroke-width="2" points="{" ".join(points)}">'
                     f'<title>{escape(name)}</title></polyline>')
        parts.append(f'<text x="{LEFT + index * 200}" y="{HEIGHT - 8}" fill="{colour}">■ {escape(name)}</text>')
    if incidents:
        parts.append(f'<text x="{WIDTH - RIGHT}" y="{HEIGHT - 8}" text-anchor="end" class="incident-key">'
                     '┆ incident (hover for what)</text>')
    parts.append("</svg>")
    return "".join(parts)
