"""What a session's QoS plot shows, for the kiosk's plots and the ward station's alike: one colour
per metric, the marks (incidents and adaptations) in a clinician's words.

One module, imported by both (the station may import the export layer, never the kiosk's UI), so a
metric has the same colour on the kiosk's screen, its PNG and the station's page.
"""

from __future__ import annotations

from basis import record
from kiosk.store.records import StoredSession

#: the metrics of the CLARC model, in the order they are drawn
METRICS = ("Performance", "Interaction", "VoiceInteractionQuality")
#: one colour per metric (hex; colour-blind-safe blue, green and purple)
METRIC_COLOURS = {"Performance": "#1b6ac9", "Interaction": "#15803d", "VoiceInteractionQuality": "#7e22ce"}
#: colours for metrics of another QoS model, in turn
OTHER_COLOURS = ("#c2410c", "#a16207", "#0e7490")
#: the colour of each kind of mark
MARK_COLOURS = {"incident": "#6b7280", "adaptation": "#b91c1c"}
#: session-log kinds shown as incidents, with the words a clinician reads
INCIDENT_WORDS = {
    "pause": "paused",
    "resume": "resumed",
    "call_doctor": "doctor called",
    "doctor_called": "doctor called",
    "doctor_call_cancelled": '"I\'m fine, carry on"',
    "clinician_continue": "continued by staff",
    "doctor_continued": "continued by staff",
    "person_lost": "patient left",
    "person_back": "patient back",
    "away_alert": "ward alerted: away",
    "unattended": "ward alerted: no answer",
    "attempt_timed_out": "no answer in time",
    "repeat": "asked to repeat",
    "abandoned": "abandoned",
}
#: adaptations in a clinician's words (a policy may name others: shown with spaces)
ADAPTATION_WORDS = {
    "voice_off": "voice answers off",
    "voice_room": "voice hard to hear in this room",
    "slow_speech": "slow speech",
    "longer_attempts": "longer attempts",
}


def metric_colour(name: str, index: int = 0) -> str:
    """The colour of metric ``name`` (``index``: its place, for a metric of another model)."""
    return METRIC_COLOURS.get(name) or OTHER_COLOURS[index % len(OTHER_COLOURS)]


@record
class Mark:
    """A vertical mark on the plot: an incident or an adaptation switching on or off."""

    t: float
    label: str
    #: "incident" or "adaptation"
    kind: str


def plot_marks(stored: StoredSession, incidents: tuple[str, ...] | None = None) -> tuple[Mark, ...]:
    """The session's marks in time order: its incidents (``incidents``: the log kinds to show,
    default all of :data:`INCIDENT_WORDS`) and every adaptation switching on or off -- except
    slow speech while voice out was off (the kiosk said nothing, so nothing was slowed)."""
    kinds = INCIDENT_WORDS.keys() if incidents is None else incidents
    marks = [
        Mark(e.t, INCIDENT_WORDS.get(e.kind, e.kind.replace("_", " ")), "incident")
        for e in stored.log
        if e.kind in kinds
    ]
    voice_out = [(e.t, e.detail == "available") for e in stored.log if e.kind == "voice_out"]
    for change in stored.adaptations:
        if change.name == "slow_speech" and not _voice_out_at(voice_out, change.t):
            continue
        words = ADAPTATION_WORDS.get(change.name, change.name.replace("_", " "))
        marks.append(Mark(change.t, f"{words} {'on' if change.active else 'off'}", "adaptation"))
    return tuple(sorted(marks, key=lambda m: m.t))


def _voice_out_at(changes: list[tuple[float, bool]], t: float) -> bool:
    """Whether voice out was on at ``t`` (on until the log says otherwise)."""
    state = True
    for when, available in changes:
        if when > t:
            break
        state = available
    return state
