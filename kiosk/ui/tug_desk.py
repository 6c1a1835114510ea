"""The Timed Up and Go in a visit at the kiosk, between the controller and the screens (issue 34).

:class:`TugDesk` is plain (no Textual, like the controller): it says when a visit's battery has a
TUG due (:meth:`due`, before the instrument that follows it), holds the running
:class:`~kiosk.core.tug.visit.TugRun`, hands it the camera's landmarks on the UI thread (the
camera's :class:`~kiosk.camera.feed.PoseFeed`, drained up to the clock's now), publishes its QoS
contexts into the visit's engine and trace, speaks the instructions and "Go" through the kiosk's
voice, stores staff's decision (``tug_results``) and then lets the visit go on. Without a camera,
or without the pose model, the run is timed by staff's stopwatch and the screens say why.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from kiosk.core.clock import Clock
from kiosk.core.visits import WALK_UP

if TYPE_CHECKING:
    from kiosk.core.session import Session
    from kiosk.core.session.battery import Battery
    from kiosk.core.tug.step import TugResult, TugSettings
    from kiosk.core.tug.visit import TugRun
    from kiosk.store.database import Store

log = logging.getLogger(__name__)


class TugDesk:
    """``battery()`` is the visit's battery now (None: no battery); ``settings()`` the site's TUG
    settings; ``camera()`` why the camera cannot time a test now (None: it can); ``poses()`` the
    camera's feed (``into(step, before)``, ``clear()``) or None; ``say(key, language)`` speaks a
    screen text of the words files (``tug_instructions``, ``tug_go``) in ``language``."""

    def __init__(
        self,
        clock: Clock,
        store: Store | None,
        *,
        battery: Callable[[], Battery | None],
        settings: Callable[[], TugSettings],
        camera: Callable[[], str | None] = lambda: "no camera on this kiosk",
        poses: Callable[[], Any] = lambda: None,
        say: Callable[[str, str], None] = lambda key, language: None,
    ) -> None:
        self._clock, self._store = clock, store
        self._battery, self._settings = battery, settings
        self.camera, self.poses, self.say = camera, poses, say
        #: the test under way (None: none)
        self.run: TugRun | None = None
        #: the last test's stored id and result (for staff and tests)
        self.stored: tuple[str | None, TugResult] | None = None
        self._session: Session | None = None
        self._step = 0
        self._then: Callable[[], None] = lambda: None
        self._said: set[str] = set()

    @property
    def busy(self) -> bool:
        return self.run is not None

    def due(self, before: Session | None, session: Session, then: Callable[[], None]) -> bool:
        """Whether a TUG comes after ``before`` (None: before the visit's first instrument) in
        ``session``'s visit; if so it starts (set-up first) and ``then()`` follows once staff decided."""
        battery = self._battery()
        step = battery.tug_after(before) if battery is not None else None
        if battery is None or step is None:
            return False
        if before is None and (session.battery is None or session.battery.index != step + 1):
            return False  # a test continued later in the visit: its TUG came before, if at all
        from kiosk.core.tug.step import TugStepError
        from kiosk.core.tug.visit import TugRun

        try:
            self.run = TugRun(
                self._clock,
                self._publish,
                walk_up=session.visit == WALK_UP,
                language=session.language,
                part=(step + 1, len(battery.ids)),
                camera=self.camera(),
                settings=self._settings(),
            )
        except TugStepError as refused:  # a walk-up visit: never offered (its battery has none)
            log.warning("Timed Up and Go not given: %s", refused)
            return False
        self._session, self._step, self._then, self._said = session, step, then, set()
        if (feed := self.poses()) is not None:
            feed.clear()  # what the camera saw before the test is not the test's
        return True

    def _publish(self, t: float, values: Mapping[str, Any]) -> None:
        """The run's contexts into the visit's QoS engine and trace, at the session's time now."""
        battery, session = self._battery(), self._session
        if battery is None or session is None:
            return
        engine, trace = battery.qos(self._step)
        declared = getattr(getattr(engine, "model", None), "contexts", ())
        known = {name: value for name, value in values.items() if name in declared}
        if engine is None or not known:
            return
        now = max(session.now(), trace[-1]["t"] if trace else 0.0)
        engine.update(now, set=known)
        trace.append({"t": now, "set": known})

    # -- what the app calls ---------------------------------------------------------------------

    def poll(self) -> None:
        """Hand the camera's landmarks so far to the run; end the run once the patient sat back."""
        run = self.run
        feed = self.poses()
        if run is None:
            if feed is not None:
                feed.clear()
            return
        if feed is not None and run.timed_by_camera:
            feed.into(run.step, before=self._clock.now())
        run.poll()

    def confirm(self, by: str) -> None:
        """Staff are beside the patient: the instructions are said in the patient's language."""
        run = self._running()
        run.confirm_staff(by)
        self._say_once("tug_instructions")

    def go(self) -> None:
        """The kiosk says "Go" (the clock starts)."""
        run = self._running()
        run.go()
        self._say_once("tug_go")

    def decide(self, decision: str, by: str, **items: Any) -> TugResult:
        """Staff's decision (and items): stored, then the visit goes on."""
        return self._done(self._running().decide(decision, by, **items))

    def skip(self, by: str, reason: str) -> TugResult:
        """Staff skip the test, saying why: stored as rejected with the reason, the visit goes on."""
        return self._done(self._running().skip(by, reason))

    def _running(self) -> TugRun:
        if self.run is None:
            from kiosk.core.tug.step import TugStepError

            raise TugStepError("no Timed Up and Go is under way")
        return self.run

    def _say_once(self, key: str) -> None:
        if self.run is not None and key not in self._said:
            self._said.add(key)
            self.say(key, self.run.language)

    def _done(self, result: TugResult) -> TugResult:
        session, battery = self._session, self._battery()
        stored = None
        if self._store is not None and session is not None:
            visit = battery.visit_id if battery is not None else None
            # how the visit began (an order's id), so the station files the TUG under that order
            stored = self._store.tug.record(session.patient_id, result, visit_id=visit, visit=session.visit)
        self.stored = (stored, result)
        self.run, then = None, self._then
        then()
        return result
