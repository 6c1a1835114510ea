"""What the kiosk does between the session and the screens, with no Textual in it.

:class:`KioskController` owns the running :class:`~kiosk.core.session.Session` and everything that
replaces it: the next patient, staff's "New patient", a test ended from the ward station, a test
continued or a visit started on the clinician screen, a test this kiosk lost (another kiosk took
it, or the store failed). All of these go through one path, :meth:`KioskController.start_over`
(or :meth:`~KioskController.swap` for a session staff chose). It also holds a session while the
clinician screens are open, renews this kiosk's lease on its session, applies station commands
and tells the station what the ward view shows.

The Textual app (:mod:`kiosk.ui.app`) routes input here and draws what the controller asks for,
through the small :class:`Screens` port; the controller is tested without Pilot for that reason.
Everything here runs on the UI thread: threads reach it only through the app.
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import sqlite3
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Protocol

from kiosk.core.answerers import answerer
from kiosk.core.channels import Channel, ChannelInput, Presence
from kiosk.core.session import Finished, NextPatient, Phase, Session, SessionEvent
from kiosk.core.visits import Order, VisitDesk
from kiosk.store.database import Store, StoredSession
from kiosk.store.lease import SessionTaken
from kiosk.store.space import can_write
from kiosk.ui.paging import PAGE_BUTTON, RemotePager, needs_paging
from kiosk.ui.tug_desk import TugDesk

log = logging.getLogger(__name__)
#: what staff read when they try to replace a test that is still going
IN_PROGRESS = "a test is in progress on this kiosk: finish it, or start a new patient, first"
#: the phases a clinician's visit pauses (the welcome and the end have nothing to time out)
_RUNNING = (Phase.FAMILIARISATION, Phase.EXPLANATION, Phase.REST, Phase.QUESTIONS)


class Screens(Protocol):
    """What the controller asks of the UI (the Textual app implements it)."""

    def redraw(self, *, rebuild: bool = False) -> None:
        """Show the screens the session calls for (``rebuild``: even if they look the same)."""

    def session_event(self, event: SessionEvent) -> None:
        """The channels follow a session event (speak a prompt, listen, stop talking)."""

    def tell_channels(self) -> None:
        """Tell the session which channels are on (a new one runs, or voice came or went)."""

    def stopped(self, reason: str) -> None:
        """Tell whoever is in front of the kiosk that the test stopped (naming no one)."""

    def close_clinician(self) -> None:
        """Close the clinician screens and show the patient's."""

    def later(self, callback: Callable[[], None]) -> None:
        """Call ``callback`` once the current event is handled."""


class KioskController:
    """The running session of one kiosk and the operations that replace, hold or end it.

    ``session`` is the first (not yet started) session. ``fresh()`` builds a session for the next
    patient and ``resume(stored)`` one continuing an interrupted test (None: this kiosk cannot);
    ``after(session)`` the session of a battery's next instrument (None: the visit is over).
    ``visits`` is a :class:`kiosk.core.visits.VisitDesk` (None: every welcome is a walk-up);
    ``sync`` the station's client, ``orders`` its order watcher and ``start_order(code)`` the call
    that starts an ordered visit (all None without a station); ``tugs`` gives a battery's Timed Up
    and Go in its place (:mod:`kiosk.ui.tug_desk`). Call :meth:`attach` before use.
    """

    def __init__(
        self,
        session: Session,
        *,
        store: Store | None = None,
        fresh: Callable[[], Session] | None = None,
        resume: Callable[[StoredSession], Session] | None = None,
        after: Callable[[Session], Session | None] | None = None,
        visits: VisitDesk | None = None,
        sync: Any = None,
        orders: Any = None,
        start_order: Callable[[str], Any] | None = None,
        tugs: TugDesk | None = None,
    ) -> None:
        self.session = session
        self.store = store
        self.fresh = fresh
        self.resume = resume
        self.after = after
        self.visits = visits
        self.sync = sync
        self.orders = orders
        self.start_order = start_order
        #: the visit's Timed Up and Go when its battery has one (None: never)
        self.tugs = tugs
        #: every session event received, in order (the clinician screens and tests read it)
        self.events: list[SessionEvent] = []
        #: why the kiosk cannot store (a full disk, a failing drive); None while it can
        self.store_fault: str | None = None
        #: why the display cannot show a test (:func:`kiosk.ui.floor.too_small`); None while it can
        self.display_fault: str | None = None
        self.view: Screens | None = None
        self._held: Session | None = None
        self._dirty = False
        #: which page of a 5- or 6-answer item the remote's 1-3 stand for (:mod:`kiosk.ui.paging`)
        self.pager = RemotePager()
        #: whether a remote is in use now, so such items show pages (the app says, from its channels)
        self.remote_in_use: Callable[[], bool] = lambda: True
        self._unsubscribe: Callable[[], None] = lambda: None

    @property
    def out_of_order(self) -> str | None:
        """Why the kiosk takes no patient now, for staff; None while it works."""
        return self.store_fault or self.display_fault

    def display_size(self, columns: int, rows: int) -> None:
        """The display is now ``columns`` x ``rows``: below :data:`kiosk.ui.floor.FLOOR` the
        kiosk takes no patient (a running test is interrupted, for staff to continue) and tells
        staff why; back above it, the welcome returns by itself."""
        from kiosk.ui.floor import too_small

        reason = too_small(columns, rows)
        if reason == self.display_fault:
            return
        self.display_fault = reason
        if reason is not None:
            log.warning("out of order: %s", reason)
            if self._busy():
                self.session_lost(reason, tell_patient=False)
        if self.view is not None:
            self._screens().redraw(rebuild=True)
        self.report_status()

    def attach(self, view: Screens) -> None:
        """Draw on ``view`` and follow the session's events from now on."""
        self.view = view
        self._unsubscribe()
        self._unsubscribe = self.session.subscribe(self._on_event)

    def _screens(self) -> Screens:
        assert self.view is not None, "attach a view first"
        return self.view

    # -- the station's threads (started and stopped with the app) ---------------------------------

    def start_station(self) -> None:
        """Start the station's client and order watcher (each runs its own thread)."""
        for part in (self.sync, self.orders):
            if part is not None:
                part.start()

    def stop_station(self) -> None:
        """Stop them (safe to call twice)."""
        for part in (self.sync, self.orders):
            if part is not None:
                part.stop()

    # -- running session operations ---------------------------------------------------------------

    def drive(self, operation: Callable[..., object], *args: object) -> None:
        """Run a session operation, then redraw if it published anything. A session another kiosk
        took over (or that was interrupted) stores nothing more here: the kiosk lets it go."""
        try:
            operation(*args)
        except SessionTaken as taken:
            self.session_lost(str(taken))
            return
        except sqlite3.Error as failed:  # the step was rolled back: the session in memory is ahead of it
            self._store_failed(failed)
            return
        if self._dirty:
            self._dirty = False
            self._screens().redraw()
        self.report_status()

    def _on_event(self, event: SessionEvent) -> None:
        self.events.append(event)
        self._dirty = True
        self._screens().session_event(event)
        if isinstance(event, Finished) and self.after is not None:
            self._screens().later(self.next_instrument)
        if isinstance(event, NextPatient):
            self._screens().later(self.next_patient)

    def forward(self, item: ChannelInput | Presence) -> None:
        """Hand an input to the session (what a number means on each screen is the session's call);
        nothing while the kiosk is out of order, and none starts a test while the welcome waits for
        staff (an ordered visit, no walk-ups). A presence report goes straight on (none in a TUG)."""
        if self.out_of_order is not None:
            return
        if isinstance(item, Presence):
            if not self.tug_busy:  # a TUG's walk is no leaving
                self.drive(self.session.handle, item)
            return
        if (self.session.phase is Phase.WELCOME and self.welcome_held()) or self.tug_busy:
            return
        if item.option is not None and self._paged_input(item) and (key := self.paged_item()) is not None:
            option = self.pager.press(key, key[2], item.option)
            if option is None:  # the remote's 4 turned the page: nothing for the session
                self._screens().redraw()
                return
            item = dataclasses.replace(item, option=option)
        self.drive(self.session.handle, item)

    def _paged_input(self, item: ChannelInput) -> bool:
        """Whether ``item`` means what the paged screen shows: the remote's 1-4, and the keys 1-4
        too (the number pressed is the number on screen; keys 5 and 6 stay options 5 and 6)."""
        if item.option is None or not self.remote_in_use():
            return False
        return item.channel is Channel.REMOTE or (item.channel is Channel.KEYBOARD and item.option <= PAGE_BUTTON)

    def paged_item(self) -> tuple[str, int | None, int] | None:
        """The item on screen when a remote reaches its answers by pages (5 or 6 options, not
        while "Is that right?" asks Yes or No), as the pager's key (id, attempt, option count)."""
        snap = self.session.snapshot()
        item = snap.item
        if snap.phase is not Phase.QUESTIONS or item is None or snap.confirming is not None:
            return None
        return (item.id, snap.attempt, len(item.options)) if needs_paging(len(item.options)) else None

    def remote_page(self) -> int:
        """The page the remote's answers are on for the item on screen (0: options 1-3)."""
        key = self.paged_item()
        return self.pager.page(key) if key is not None else 0

    def turn_page(self) -> None:
        """The page button was touched on screen: the other three answers (as the remote's 4)."""
        if (key := self.paged_item()) is not None:
            self.pager.turn(key)
            self._screens().redraw()

    def start_in(self, language: str) -> None:
        """The patient chose a language on the welcome: the test starts in it."""
        if self.out_of_order is not None or self.welcome_held():
            return

        def start() -> None:
            self.session.choose_language(language)
            self.session.start()

        self.drive(start)

    def greet(self) -> None:
        """A fresh session's welcome is said, and listened to: "start", or a language's name
        (not while the welcome waits for staff to confirm an ordered visit)."""
        if self.session.phase is Phase.WELCOME and not self.welcome_held():
            self.drive(self.session.welcome)

    # -- replacing the session: the one way to start over ---------------------------------------

    def swap(self, session: Session) -> None:
        """Run ``session`` from now on; the one it replaces is let go (released if finished,
        interrupted if still running)."""
        old, self.session = self.session, session
        self._unsubscribe()
        if self.store is not None and old.id != session.id:
            with contextlib.suppress(sqlite3.Error):  # else keep_session lets it go later
                self.store.release(old.id)
        self._unsubscribe = session.subscribe(self._on_event)
        self._screens().tell_channels()
        if self.visits is not None:
            self.visits.next_visit()

    def start_over(self, *, abandon: bool = False, reason: str | None = None) -> None:
        """The welcome, with a fresh session, for the next patient. ``abandon``: the session it
        replaces is stored as abandoned (with ``reason``) first; the session decides whether it
        counts (:meth:`Session.abandon`). Without a way to build one the session stays."""
        if abandon:
            try:
                self.session.abandon(reason) if reason is not None else self.session.abandon()
            except SessionTaken:
                pass  # another kiosk holds it now: nothing of it is this kiosk's to end
        fresh = self.fresh() if self.fresh is not None else None
        if fresh is not None:
            self.swap(fresh)
        self._screens().redraw(rebuild=True)
        if fresh is not None:
            self.greet()

    tug_busy = property(lambda self: self.tugs is not None and self.tugs.busy, doc="A TUG is under way.")

    def next_instrument(self) -> None:
        """The running instrument finished: the visit's next one starts on its rest screen, after a
        TUG due between them; after the last, nothing (the end screen; after a TUG, the welcome)."""
        finished = self.session
        if finished.finished and self.tugs is not None and self.tugs.due(finished, finished, self._after_tug):
            self._screens().redraw(rebuild=True)
            return
        self._next_after(finished)

    def _after_tug(self) -> None:
        if not self._next_after(self.session):
            self.next_patient()
        self._screens().redraw(rebuild=True)

    def _next_after(self, finished: Session) -> bool:
        after = self.after(finished) if self.after is not None and finished.finished else None
        if after is None:
            return False
        self.session = after
        self._unsubscribe()
        if self.store is not None:
            with contextlib.suppress(sqlite3.Error):
                self.store.release(finished.id)
        self._unsubscribe = after.subscribe(self._on_event)
        self._screens().tell_channels()
        self.drive(after.start)
        return True

    def next_patient(self) -> None:
        """The end screen was shown long enough (the session's :class:`NextPatient`): the welcome
        for the next patient; the finished result stays in the store for staff."""
        if self.fresh is not None and self.session.finished and not self.tug_busy:
            self.start_over()

    @property
    def can_start_new_session(self) -> bool:
        """A fresh session for the next patient can be built."""
        return self.fresh is not None

    def start_new_session(self) -> None:
        """Staff start over for the next patient (clinician screen, "New patient")."""
        if self.fresh is None:
            return
        self.start_over(abandon=True)
        self._screens().close_clinician()

    def end_session(self, reason: str) -> None:
        """Staff end the running test (stored as abandoned, with why); the welcome is next."""
        self.start_over(abandon=True, reason=reason)
        self.report_status()

    def session_lost(self, reason: str, *, tell_patient: bool = True) -> None:
        """This kiosk may no longer record in its session: say so plainly (naming no one: the
        next patient may be reading) and start over."""
        if tell_patient:
            self._screens().stopped(reason)
        self.start_over()

    def _busy(self) -> bool:
        return self.session.phase is not Phase.WELCOME and not self.session.finished

    # -- the clinician's hold -------------------------------------------------------------------

    @property
    def held_for_clinician(self) -> bool:
        """The session is paused because the clinician screens are open (not by the patient)."""
        return self._held is self.session and self.session.paused

    def hold(self) -> None:
        """Pause a running session while the clinician screens are open, so nothing times out
        unseen underneath (one already paused or halted stays as it is)."""
        session = self.session
        if session.phase in _RUNNING and not (session.paused or session.halted):
            self.drive(session.pause)
            self._held = session if session.paused else None

    def release(self) -> None:
        """Resume the session the clinician screens paused (not one the patient paused)."""
        if self.held_for_clinician and not self.session.halted:
            self.drive(self.session.resume)
        self._held = None

    def clinician_continue(self) -> None:
        """A clinician continues a session halted by call-doctor (or paused)."""
        self.drive(self.session.clinician_continue)

    def person_lost(self, detail: str = "clinician screen") -> None:
        """Staff say the patient left the kiosk ("Patient away": here, or from the ward station)."""
        self.drive(self.session.person_lost, detail)

    def person_back(self, detail: str = "clinician screen") -> None:
        """Staff say the patient is back in front of the kiosk."""
        self.drive(self.session.person_back, detail)

    def set_adaptation(self, enabled: bool) -> None:
        """A clinician switches live adaptation on or off for this session."""
        self.drive(self.session.set_adaptation_enabled, enabled)

    # -- tests staff continue, visits staff or the station start ---------------------------------

    def interrupted_tests(self) -> list[StoredSession]:
        """The tests staff may continue here (their kiosk stopped, or they grew too old), newest first."""
        return self.store.unfinished_sessions() if self.store is not None else []

    def continue_test(self, session_id: str) -> str | None:
        """Staff continue an interrupted test on this kiosk (clinician screen, behind the PIN).
        Returns why not, as a sentence for staff, or None once it continues."""
        if self.store is None or self.resume is None:
            return "this kiosk stores no sessions"
        if self._busy():
            return IN_PROGRESS
        try:
            stored = self.store.continue_session(session_id)
        except (SessionTaken, ValueError, KeyError) as refused:
            return str(refused.args[0] if isinstance(refused, KeyError) else refused)
        self._begin(self.resume(stored))
        return None

    def start_staff_visit(
        self, patient_id: str, language: str, relative: bool, relationship: str | None = None
    ) -> str | None:
        """Staff start a visit for the identifier they typed (clinician screen): why not, or None;
        ``relationship``: how the person answering for the patient is related to them."""
        if self.visits is None:
            return "this kiosk cannot start visits for a patient identifier"
        if self._busy():
            return IN_PROGRESS
        related = answerer(relationship) if relationship is not None else None
        session, why = self.visits.for_staff(patient_id, language, relative, related)
        if session is None:
            return why
        self._begin(session, session.answered_by)
        return None

    def _begin(self, session: Session, *start: object) -> None:
        self.swap(session)
        self._screens().close_clinician()
        self._start(*start)

    def _start(self, *start: object) -> None:
        """Start the visit's session, after a Timed Up and Go due before its first instrument."""
        session, begin = self.session, lambda: self.drive(self.session.start, *start)
        if self.tugs is not None and session.phase is Phase.WELCOME and self.tugs.due(None, session, begin):
            self._screens().redraw(rebuild=True)
        else:
            begin()

    def welcome_held(self) -> bool:
        """The welcome waits for staff to confirm an ordered visit (or the site allows no walk-up)."""
        return self.visits is not None and self.visits.holds_welcome()

    def orders_changed(self, orders: Sequence[Order], problems: Sequence[str] = ()) -> None:
        """The station's list of visits for this kiosk: the welcome follows it."""
        if self.visits is not None and self.visits.set_orders(orders, problems) and self.session.phase is Phase.WELCOME:
            self._screens().redraw()

    def order_started(self, order: Order) -> None:
        """The station started the visit: a session for its patient, in its language, begins."""
        if self.visits is not None and self.session.phase is Phase.WELCOME:
            self.swap(self.visits.for_order(order))
            self._start(order.answered_by)

    def walk_up(self) -> None:
        """Staff let a walk-up patient start at the welcome."""
        if self.visits is not None and self.visits.choose_walk_up():
            self.greet()
            self._screens().redraw()

    # -- the ward station ------------------------------------------------------------------------

    def report_status(self) -> None:
        """Give the station's client what the ward view shows of this kiosk (sent when it changes)."""
        if self.sync is not None:
            from kiosk.sync.commands import live_status

            self.sync.set_status({**live_status(self.session), "out_of_order": self.out_of_order})

    def station_command(self, command: Any) -> tuple[str, str | None] | None:
        """Apply a station command (on the UI thread: the app hands it over from the client's)."""
        from kiosk.sync.commands import apply_command

        return apply_command(self, dict(command))

    # -- this kiosk's hold on its session, and a store that fails ---------------------------------

    def keep_session(self) -> None:
        """Renew this kiosk's hold on its session and interrupt the tests whose kiosk is gone (a
        timer calls this); a running session this kiosk no longer holds is let go."""
        assert self.store is not None
        session = self.session
        try:
            self.store.renew()
            self.store.release_others(session.id)  # one this kiosk dropped when it could not write
            self.store.interrupt_stale()
            why = None if session.phase is Phase.WELCOME or session.finished else self.store.why_not_held(session.id)
        except sqlite3.Error:
            return  # the database is busy or failing: the next round tries again
        if why is not None:
            self.session_lost(why)
        elif self.store_fault is not None and can_write(Path(self.store.path).parent):
            self.store_fault = None  # space was freed (or the lock let go): the welcome is back
            self._screens().redraw(rebuild=True)
            self.report_status()

    def _store_failed(self, failed: sqlite3.Error) -> None:
        """The store refused a step (a full disk, a failing drive, a lock held too long; what it
        refused was rolled back, what was stored stays for staff to continue). The kiosk takes no
        patient until it can write again: the patient sees one calm out-of-order screen, staff
        the reason on the clinician screen and the station (:meth:`keep_session` recovers)."""
        self.store_fault = f"the kiosk could not store its last step ({failed})"
        self.session_lost(self.store_fault, tell_patient=False)
        self.report_status()
