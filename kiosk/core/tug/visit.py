"""The Timed Up and Go as a step of a visit at the kiosk: what the screens show and what staff do,
around a :class:`~kiosk.core.tug.step.TugStep` (issue 34, part 3).

:class:`TugRun` is pure, like the step: an injected clock, frames handed in by whoever owns the
camera's feed. It adds what the screens need and the step does not know: whether the camera can
time the test here (else staff time it by stopwatch, and the screens say why), the whole-body
check remembered at the chair and at the 3 m line, the live phase ("seated", "up and walking",
"seated again"), when the run is over, and a skip with a stated reason. The patient's words come
from the words files (``tug_*``), in the visit's language.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from kiosk.core.clock import Clock
from kiosk.core.tug.step import PRE_GO_S, Publish, TugResult, TugSettings, TugStage, TugStep, TugStepError
from kiosk.core.words.placeholders import fill

#: the two places staff check the whole body is seen before the start
SPOTS = ("chair", "line")
#: the live phase's key in the words files (``tug_phase_<key>``)
LIVE_PHASES = ("ready", "seated", "up", "back", "over")
#: seconds the patient must stay seated back before the run ends by itself
SETTLE_S = 1.0
#: the longest run the kiosk records (a run past it ends: staff time it by stopwatch or reject)
MAX_RUN_S = 180.0


class TugRun:
    """One Timed Up and Go at the kiosk, for the visit at ``step_index`` of its steps.

    ``camera``: None when the camera times the test, else why it cannot (the run is then timed by
    staff's stopwatch only). ``part`` is (number, count) of the visit's steps, for "Part 2 of 3"."""

    def __init__(
        self,
        clock: Clock,
        publish: Publish,
        *,
        walk_up: bool,
        language: str,
        part: tuple[int, int],
        camera: str | None,
        settings: TugSettings | None = None,
        fps: float = 30.0,
    ) -> None:
        self.step = TugStep(clock, publish, walk_up=walk_up, settings=settings, fps=fps)
        self._clock = clock
        self.language, self.part = language, part
        #: why the camera cannot time this test (None: it can)
        self.camera_off = camera
        #: the whole-body check as staff last marked it at each spot ("" when the body was seen)
        self.checked: dict[str, str] = {}
        #: why staff skipped the test (then nothing is timed)
        self.skipped: str | None = None
        self._seated_since: float | None = None

    # -- the set-up -----------------------------------------------------------------------------

    @property
    def stage(self) -> TugStage:
        return self.step.stage

    @property
    def timed_by_camera(self) -> bool:
        return self.camera_off is None

    @property
    def framing(self) -> str:
        """The live whole-body check: "" when the whole body is seen, else what is wrong."""
        if self.camera_off is not None:
            return f"no camera: {self.camera_off}"
        return self.step.framing

    def check_spot(self, spot: str) -> str:
        """Staff mark the live check at ``spot`` (the chair, the 3 m line): what it found ("" ok)."""
        if spot not in SPOTS:
            raise TugStepError(f"spot {spot!r}: one of {', '.join(SPOTS)}")
        self.checked[spot] = self.framing
        return self.checked[spot]

    @property
    def set_up(self) -> bool:
        """The whole body was seen at the chair and at the 3 m line (always true without a camera:
        there is nothing to check, and the screens say the test is timed by stopwatch)."""
        return self.camera_off is not None or all(self.checked.get(spot) == "" for spot in SPOTS)

    def confirm_staff(self, by: str) -> None:
        """Staff confirm they are beside the patient; with a camera, only once the body was seen
        at both spots."""
        if not self.set_up:
            raise TugStepError("check that the whole body is seen at the chair and at the 3 m line first")
        self.step.confirm_staff(by.strip())

    def go(self) -> float:
        """The kiosk says "Go": the clock starts."""
        return self.step.go()

    # -- the run --------------------------------------------------------------------------------

    def frame(self, t: float, landmarks: Any, width: int, height: int) -> None:
        if self.camera_off is None:
            self.step.frame(t, landmarks, width, height)

    @property
    def live(self) -> str:
        """The live phase's key (:data:`LIVE_PHASES`)."""
        stage = self.step.stage
        if stage in (TugStage.SETUP, TugStage.READY):
            return "ready"
        if stage is not TugStage.RUNNING:
            return "over"
        if self.step.seated_again:
            return "back"
        return "up" if self.step.up else "seated"

    def elapsed(self) -> float | None:
        """Seconds since "Go" (None before it)."""
        go_t = self.step.go_t
        return None if go_t is None else self._clock.now() - go_t

    def poll(self) -> bool:
        """The run ends by itself once the patient sat back for :data:`SETTLE_S` (with a camera),
        or past :data:`MAX_RUN_S`; True when it just ended."""
        if self.step.stage is not TugStage.RUNNING:
            return False
        now = self._clock.now()
        if self.step.seated_again:
            self._seated_since = now if self._seated_since is None else self._seated_since
        if (self._seated_since is not None and now - self._seated_since >= SETTLE_S) or (
            (self.elapsed() or 0.0) >= MAX_RUN_S
        ):
            self.step.finish()
            return True
        return False

    def finish(self) -> None:
        """Staff end the run (the patient sat back; or the stopwatch is stopped)."""
        self.step.finish()

    # -- staff's decision -----------------------------------------------------------------------

    def decide(
        self,
        decision: str,
        by: str,
        stopwatch_s: float | None = None,
        get_up_go: int | None = None,
        walking_aid: str | None = None,
    ) -> TugResult:
        """Staff items, then staff's decision (the step's :meth:`~TugStep.decide`); without a
        camera only a stopwatch time or a rejection."""
        if decision == "accepted" and self.camera_off is not None:
            raise TugStepError("no camera timed this test: enter the stopwatch time or reject it")
        self.step.rate(get_up_go, walking_aid)
        return self.step.decide(decision, by.strip(), stopwatch_s)

    def skip(self, by: str, reason: str) -> TugResult:
        """Staff skip the test, saying why: a rejected result with that reason, nothing timed."""
        if self.step.stage is TugStage.DONE:
            raise TugStepError("the test is over")
        if not by.strip() or not reason.strip():
            raise TugStepError("who skips it and why")
        self.skipped = reason.strip()
        settings = self.step.settings
        result = TugResult(
            confirmed_by="",
            confirmed_t=self._clock.now(),
            go_t=self.step.go_t,
            decision="rejected",
            decided_by=by.strip(),
            total_s=None,
            method=None,
            camera_total_s=None,
            phases=(),
            reasons=(f"skipped: {self.skipped}",),
            person_share=0.0,
            body_cut_off=False,
            turn_seen=False,
            threshold_s=settings.threshold_s,
        )
        self.step.stage = TugStage.DONE
        return result

    # -- what the patient reads and hears -------------------------------------------------------

    def words(self, texts: Mapping[str, str]) -> dict[str, str]:
        """The patient screen's texts from a language's screen words (``tug_*``)."""
        number, count = self.part
        return {
            "part": fill(texts["tug_part"], number=number, total=count),
            "title": texts["tug_title"],
            "instructions": texts["tug_instructions"],
            "phase": texts[f"tug_phase_{self.live}"],
        }


__all__ = ["LIVE_PHASES", "PRE_GO_S", "SPOTS", "TugRun"]
