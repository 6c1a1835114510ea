"""The Timed Up and Go as a step of a visit: staff confirm they are there, the kiosk says "Go",
pose frames come in, the analysis times the course, staff decide.

Pure (issue 34, part 3): time comes from an injected clock, contexts go out through ``publish(t,
values)`` and frames come in through :meth:`TugStep.frame` (the camera channel's ``on_pose``, or a
landmark file in a replay). Why a step of its own and not a questionnaire: it has no questions; what
it shares with one is the clock, the QoS engine and the stored visit.

Contexts (the CLARC model's Get Up & Go contexts, docs/qos-model.md), each published on change:
``PersonIsNextToChair`` true once the whole body is seen before "Go" (false when it is lost);
``PersonIsSeated`` true at "Go" when the patient sits, false on rising, true again when seated
back; ``PersonGetsUp`` true while up; ``Scored`` true when staff accept a time (camera or
stopwatch), false when they reject it. The live posture here only drives these contexts; the time
is the analysis' (:func:`kiosk.core.tug.analysis.analyse`) on the whole recording.

Never a picture: frames are landmarks only, and the result keeps them only when the site turns
``keep_landmarks`` on. The fall-risk wording is "above the site's threshold", never a diagnosis.
"""

from __future__ import annotations

import statistics
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from enum import Enum
from typing import Any

from basis import record
from kiosk.core.clock import Clock
from kiosk.core.tug.analysis import MIN_LEGS_SHARE, MIN_RISE, Phase, TugAnalysis, analyse
from kiosk.core.tug.framing import framing_problem
from kiosk.core.tug.landmarks import INDEX, Landmark, PoseFrame, PoseSequence

#: the most quoted fall-risk cut-off (Barry et al. 2014); a site sets its own
DEFAULT_THRESHOLD_S = 13.5
#: the Get Up & Go rating (Mathias, Nayak & Isaacs 1986): 1 normal .. 5 severely abnormal
GET_UP_GO = {
    1: "normal",
    2: "very slightly abnormal",
    3: "mildly abnormal",
    4: "moderately abnormal",
    5: "severely abnormal",
}
WALKING_AIDS = ("none", "stick", "crutches", "frame", "rollator", "other")
DECISIONS = ("accepted", "stopwatch", "rejected")
#: live posture: up when the hips rose this much (torso lengths) over the seated height, held this long
UP_HELD_S = 0.3
#: ...and seated again within this of the seated height, held this long
SEATED_BAND = 0.15
SEATED_HELD_S = 0.5
#: frames kept from before "Go": the analysis reads the seated rest there (docs/tug.md), not the set-up
PRE_GO_S = 2.0

Publish = Callable[[float, Mapping[str, Any]], None]


class TugStage(Enum):
    SETUP = "setup"  # the clinician sets the camera up; waiting for staff to confirm
    READY = "ready"  # staff confirmed; waiting for "Go"
    RUNNING = "running"  # "Go" said; frames recorded
    ANALYSED = "analysed"  # the analysis ran; waiting for staff's decision
    DONE = "done"


class TugStepError(ValueError):
    """An action the step does not take now (the message says why, for staff)."""


@record
class TugSettings:
    """The site's choices: its fall-risk threshold (s) and whether landmarks are kept."""

    threshold_s: float = DEFAULT_THRESHOLD_S
    keep_landmarks: bool = False


@record
class TugResult:
    """What a Timed Up and Go leaves in the visit: the time taken (``total_s``, by ``method``
    camera or stopwatch; None when rejected), the camera's analysis and quality flags, who did what."""

    confirmed_by: str
    confirmed_t: float
    go_t: float | None
    decision: str
    decided_by: str
    total_s: float | None
    method: str | None
    camera_total_s: float | None
    phases: tuple[Phase, ...]
    reasons: tuple[str, ...]
    person_share: float
    body_cut_off: bool
    turn_seen: bool
    threshold_s: float
    get_up_go: int | None = None
    walking_aid: str | None = None
    #: the landmarks (never pictures), only where the site keeps them
    landmarks: PoseSequence | None = None

    @property
    def above_threshold(self) -> bool | None:
        return None if self.total_s is None else self.total_s > self.threshold_s

    def wording(self) -> str:
        """The sentence staff see: the time and where it stands against the site's threshold."""
        if self.total_s is None:
            return "No time taken (rejected)."
        side = "above" if self.above_threshold else "not above"
        return f"{self.total_s:.1f} s, {side} the site's threshold ({self.threshold_s:g} s)."


def posture_lift(landmarks: Sequence[Landmark], height: int) -> tuple[float, float] | None:
    """(ankles minus hips, hips minus shoulders) heights in pixels, or None when not all are seen."""

    def mid_y(part: str) -> float | None:
        ys = [
            landmarks[INDEX[f"{side}_{part}"]][1]
            for side in ("left", "right")
            if landmarks[INDEX[f"{side}_{part}"]][3] >= 0.5
        ]
        return statistics.fmean(ys) * height if ys else None

    shoulder, hip, ankle = mid_y("shoulder"), mid_y("hip"), mid_y("ankle")
    if shoulder is None or hip is None or ankle is None or hip - shoulder <= 0:
        return None
    return ankle - hip, hip - shoulder


class TugStep:
    """One Timed Up and Go of a visit (see the module's doc). ``walk_up``: the visit began at the
    kiosk without staff, where the test is never offered (it needs staff beside the patient)."""

    def __init__(
        self,
        clock: Clock,
        publish: Publish,
        *,
        walk_up: bool,
        settings: TugSettings | None = None,
        fps: float = 30.0,
    ) -> None:
        if walk_up:
            raise TugStepError(
                "the Timed Up and Go is not offered at a walk-up visit: it needs staff beside the patient"
            )
        self._clock, self._publish = clock, publish
        self.settings = settings or TugSettings()
        self.fps = fps
        self.stage = TugStage.SETUP
        self._size = (0, 0)
        self._frames: list[PoseFrame] = []
        self._published: dict[str, bool] = {}
        self._confirmed: tuple[str, float] | None = None
        self._go_t: float | None = None
        self._seat: tuple[float, float] | None = None  # seated lift and the torso at the chair
        self._since: float | None = None  # when the live posture started to differ
        self._up = False
        self._levels: deque[float] = deque(maxlen=max(3, round(0.2 * fps)))
        self.framing = "nobody in the picture"
        self.analysis: TugAnalysis | None = None
        self._result: TugResult | None = None
        self._rating: tuple[int | None, str | None] = (None, None)

    # -- frames ---------------------------------------------------------------------------------

    def frame(self, t: float, landmarks: Sequence[Landmark] | None, width: int, height: int) -> None:
        """One frame's landmarks (None: nobody found); ``t`` on the clock's time. Recorded from the
        set-up to the end of the run; the contexts follow the live posture."""
        if self.stage in (TugStage.ANALYSED, TugStage.DONE):
            return
        if self._frames and t <= self._frames[-1].t:
            return
        self._size = (width, height)
        marks = tuple(landmarks) if landmarks is not None else None
        self._frames.append(PoseFrame(t=t, landmarks=marks))
        if self.stage is not TugStage.RUNNING:
            if self._frames[0].t < t - PRE_GO_S:  # the set-up (staff placing the camera, the patient
                self._frames = [f for f in self._frames if f.t >= t - PRE_GO_S]  # walking to the chair)
            self.framing = framing_problem(marks)
            self._set(t, "PersonIsNextToChair", not self.framing)
            return
        self._follow(t, marks, height)

    def _follow(self, t: float, marks: Sequence[Landmark] | None, height: int) -> None:
        lift = posture_lift(marks, height) if marks is not None else None
        if lift is None:
            return
        if self._seat is None:
            self._seat = lift
            return
        seat, torso = self._seat
        # a running median over 0.2 s: one frame with a landmark thrown off decides nothing
        self._levels.append((lift[0] - seat) / torso)
        level = statistics.median(self._levels)
        changed = level > MIN_RISE if not self._up else level < SEATED_BAND
        if not changed:
            self._since = None
            return
        self._since = t if self._since is None else self._since
        if t - self._since < (SEATED_HELD_S if self._up else UP_HELD_S):
            return
        self._up, self._since = not self._up, None
        self._set(t, "PersonGetsUp", self._up, PersonIsSeated=not self._up)

    def _set(self, t: float, name: str, value: bool, **more: bool) -> None:
        """Publish the values that changed, as one batch at ``t`` (a false before any true is not news)."""
        changed = {}
        for key, new in {name: value, **more}.items():
            if self._published.get(key) is new:
                continue
            first = key not in self._published
            self._published[key] = new
            if new or not first or key == "Scored":
                changed[key] = new
        if changed:
            self._publish(t, changed)

    @property
    def last_landmarks(self) -> tuple[Landmark, ...] | None:
        """The latest frame's landmarks (None: no frame yet, or nobody in it): the live preview."""
        return self._frames[-1].landmarks if self._frames else None

    @property
    def up(self) -> bool:
        """The live posture: the patient is up (risen and not yet seated back)."""
        return self._up

    @property
    def seated_again(self) -> bool:
        """The patient rose and sat back down (the run can be finished)."""
        return self.stage is TugStage.RUNNING and self._published.get("PersonGetsUp") is False

    # -- staff and the patient ------------------------------------------------------------------

    def confirm_staff(self, by: str) -> None:
        """Staff ``by`` confirm they are beside the patient (stored with the result); asked before
        every start."""
        if self.stage is not TugStage.SETUP:
            raise TugStepError(f"staff confirm before the start, not when {self.stage.value}")
        if not by.strip():
            raise TugStepError("who confirms: a staff member's name or code")
        self._confirmed = (by, self._clock.now())
        self.stage = TugStage.READY

    def go(self) -> float:
        """The kiosk says "Go": the clock starts (returns ``go_t``)."""
        if self.stage is not TugStage.READY:
            raise TugStepError(
                "'Go' needs staff's confirmation first" if self.stage is TugStage.SETUP else "already started"
            )
        self._go_t = self._clock.now()
        self.stage = TugStage.RUNNING
        seated = [f for f in self._frames[-int(self.fps) :] if f.landmarks is not None]
        lifts = [x for x in (posture_lift(f.landmarks, self._size[1]) for f in seated if f.landmarks) if x]
        if lifts:
            self._seat = (statistics.median(x[0] for x in lifts), statistics.median(x[1] for x in lifts))
        self._set(self._go_t, "PersonIsSeated", True)
        return self._go_t

    def finish(self) -> TugAnalysis:
        """The run is over (seated back, or staff end it): the analysis of everything recorded."""
        if self.stage is not TugStage.RUNNING:
            raise TugStepError("nothing to finish: the test has not started")
        self.analysis = analyse(self._sequence())
        self.stage = TugStage.ANALYSED
        return self.analysis

    def rate(self, get_up_go: int | None = None, walking_aid: str | None = None) -> None:
        """Staff items: the Get Up & Go rating (1-5) and the walking aid used."""
        if get_up_go is not None and get_up_go not in GET_UP_GO:
            raise TugStepError(f"Get Up & Go rating {get_up_go}: 1 to 5")
        if walking_aid is not None and walking_aid not in WALKING_AIDS:
            raise TugStepError(f"walking aid {walking_aid!r}: one of {', '.join(WALKING_AIDS)}")
        self._rating = (get_up_go, walking_aid)
        if self._result is not None:
            self._result = replace(self._result, get_up_go=get_up_go, walking_aid=walking_aid)

    def decide(self, decision: str, by: str, stopwatch_s: float | None = None) -> TugResult:
        """Staff ``by`` accept the camera's time, enter a stopwatch time instead, or reject."""
        if self.stage is not TugStage.ANALYSED or self.analysis is None or self._confirmed is None:
            raise TugStepError("staff decide once the test is over")
        if decision not in DECISIONS:
            raise TugStepError(f"decision {decision!r}: one of {', '.join(DECISIONS)}")
        if not by.strip():
            raise TugStepError("who decides: a staff member's name or code")
        analysis = self.analysis
        if decision == "accepted" and not analysis.valid:
            raise TugStepError("the camera gave no valid time: enter a stopwatch time or reject")
        if decision == "stopwatch" and (stopwatch_s is None or not 0 < stopwatch_s < 600):
            raise TugStepError("a stopwatch time in seconds (more than 0, under 600)")
        total = {"accepted": analysis.total_s, "stopwatch": stopwatch_s, "rejected": None}[decision]
        quality = analysis.quality
        legs = quality.get("legs_share")
        self._result = TugResult(
            confirmed_by=self._confirmed[0],
            confirmed_t=self._confirmed[1],
            go_t=self._go_t,
            decision=decision,
            decided_by=by,
            total_s=total,
            method={"accepted": "camera", "stopwatch": "stopwatch"}.get(decision),
            camera_total_s=analysis.total_s,
            phases=analysis.phases,
            reasons=analysis.reasons,
            person_share=float(quality.get("person_share", 0.0)),
            body_cut_off=legs is None or legs < MIN_LEGS_SHARE or any("legs" in r for r in analysis.reasons),
            turn_seen=bool(quality.get("turn_seen", False)),
            threshold_s=self.settings.threshold_s,
            get_up_go=self._rating[0],
            walking_aid=self._rating[1],
            landmarks=self._sequence() if self.settings.keep_landmarks else None,
        )
        self.stage = TugStage.DONE
        self._set(self._clock.now(), "Scored", decision != "rejected")
        return self._result

    @property
    def go_t(self) -> float | None:
        """When the kiosk said "Go" (None: not yet)."""
        return self._go_t

    @property
    def result(self) -> TugResult | None:
        return self._result

    def _sequence(self) -> PoseSequence:
        width, height = self._size
        return PoseSequence(fps=self.fps, width=width, height=height, go_t=self._go_t, frames=tuple(self._frames))
