"""How well voice is heard in the room the kiosk stands in: a running share of the voice hearings
that worked, kept across patients.

A hearing that worked (a voice answer stored, a call by voice confirmed) counts 1; one that did not
counts 0: speech heard but not understood, an answer the patient turned down at "I heard: ...", a
"yes" too unsure to act on, a call by voice the patient did not want. The measure is their
exponentially weighted mean (:data:`WEIGHT` on the newest, from :data:`START`). It belongs to the
kiosk, not to one patient, so the next patient in a room where voice fails (a tiled day room, talk
nearby) is steered to touch or the remote after fewer failures of their own. The live adaptation
reads it as the metric :data:`METRIC` after every hearing (``kiosk/core/adaptation.yaml``, rule
``voice_room``). Why: in a reverberant room 7 % of English voice answers were stored right and no
real call got through (issue 33).
"""

from __future__ import annotations

#: the metric name adaptation rules watch (beside the QoS model's properties)
METRIC = "VoiceHeard"
#: where a new kiosk starts: neither good nor bad news about its room yet, but above voice_room's
#: threshold, so a few failures are needed before anything changes
START = 0.75
#: the weight of the newest hearing: about the last five count
WEIGHT = 0.3
#: what staff read (the clinician screen, the ward tile) while the kiosk steers patients to touch
STAFF_NOTICE = "Voice is not working well in this room: the patient is asked to touch"


class RoomHearing:
    """The room's voice measure, fed one hearing at a time. Pure: no clock, no threads."""

    def __init__(self, value: float = START) -> None:
        self.value = value
        #: hearings counted since the kiosk started
        self.hearings = 0

    def add(self, worked: bool) -> float:
        """Count one hearing; returns the measure now."""
        self.value = (1 - WEIGHT) * self.value + WEIGHT * (1.0 if worked else 0.0)
        self.hearings += 1
        return self.value
