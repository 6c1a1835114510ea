"""The one place a kiosk is put together: :func:`make_kiosk`.

`kiosk run` (:mod:`kiosk.commands.run`), the UI tests and the benches all build their kiosk here,
so what a test drives is what a ward runs: the same sessions for the next patient and for a
continued test, the same visits desk, the same station wiring. What differs is injected: the
clock (a :class:`~kiosk.core.clock.SimClock` in tests), the store, and the channels this machine
has (:class:`~kiosk.ui.channels.KioskChannels`).
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import field
from typing import TYPE_CHECKING, Any

from basis import record
from kiosk.config import site_from_config, tug_settings
from kiosk.core.adaptation import Adaptation, Policy, load_policy
from kiosk.core.answerers import walk_up_instruments
from kiosk.core.clock import Clock
from kiosk.core.pin import PinGuard
from kiosk.core.qos_model import load_kiosk_model
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.room import RoomHearing
from kiosk.core.session import Session, Watching
from kiosk.core.session.battery import Battery, Instrument
from kiosk.core.visits import STAFF, TUG, WALK_UP, VisitDesk
from kiosk.store.database import Store, StoredSession, new_patient_id
from kiosk.store.pin_files import PinFiles
from kiosk.ui.app import POLL_INTERVAL, KioskApp
from kiosk.ui.channels import KioskChannels
from kiosk.ui.controller import KioskController
from kiosk.ui.tug_desk import TugDesk
from kiosk.ui.widgets.text import ui_text

if TYPE_CHECKING:
    from kiosk.config import Config
    from qos import Model


@record
class KioskParts:
    """What a configuration names and every session shares: the questionnaire (a battery's
    first instrument), the QoS model and the adaptation policy (None: adaptation off); and the
    battery: every instrument in order with the name of its own QoS model (None: ``model``),
    ``models`` holding each such model loaded; ``steps``: the configured visit's ids in order, the
    Timed Up and Go's among them (empty: the instruments')."""

    questionnaire: Questionnaire
    model: Model
    policy: Policy | None
    instruments: tuple[tuple[Questionnaire, str | None], ...] = ()
    models: Mapping[str, Model] = field(default_factory=dict)
    steps: tuple[str, ...] = ()

    @classmethod
    def load(cls, config: Config) -> KioskParts:
        """Load them; raises QuestionnaireError, ConfigError, ModelError or PolicyError (one
        sentence, with the file and where) for a bad file."""
        from kiosk.config import configured_instruments, configured_steps, offered_to_patients

        # a site offers patients only validated translations and those it accepts, per instrument
        configured = configured_instruments(config)
        instruments = tuple((offered_to_patients(config, q), name) for q, name in configured)
        model = load_kiosk_model(config.qos_model)
        models = {name: load_kiosk_model(name) for _, name in instruments if name is not None}
        policy = load_policy(config.adaptation_policy, model=model) if config.adaptation else None
        return cls(instruments[0][0], model, policy, instruments, models, configured_steps(config, configured))

    def battery(self, ids: Sequence[str] | None = None) -> list[Instrument]:
        """The instruments of a visit, in order (a battery of one without ``instruments:``);
        ``ids``: those instruments, in that order (a station's order)."""
        given = [Instrument(q, name) for q, name in self.instruments or ((self.questionnaire, None),)]
        if ids is None:
            return given
        by_id = {i.questionnaire.id: i for i in given}
        return [by_id[i] for i in ids if i in by_id] or given

    def visit_steps(self, ids: Sequence[str] | None = None) -> tuple[str, ...]:
        """The steps of a visit: ``ids`` (an order's) as far as this kiosk gives them, the Timed Up
        and Go's id kept in its place; without ``ids`` the configured visit's."""
        given = [i.questionnaire.id for i in self.battery(ids)]
        if ids is None:
            return self.steps or tuple(given)
        return tuple(i for i in ids if i in given or i == TUG) if any(i in given for i in ids) else tuple(given)

    @property
    def ids(self) -> list[str]:
        """The ids of the instruments this kiosk gives (an order's instruments are checked against
        them), the Timed Up and Go's always among them: staff can time it at least by stopwatch."""
        return [*(i.questionnaire.id for i in self.battery()), TUG]

    @property
    def languages(self) -> list[str]:
        """The languages every instrument of the battery has."""
        return [lang for lang in self.questionnaire.languages if all(lang in q.languages for q, _ in self.instruments)]

    def model_for(self, name: Hashable | None) -> Model:
        """The QoS model an instrument runs on (None: the kiosk's)."""
        return self.models[str(name)] if name is not None else self.model


class SessionMaker:
    """Builds this kiosk's sessions: a fresh one for the next patient, one continuing a stored
    test. ``patient_ids()`` gives each walk-up patient a pseudonymous id."""

    def __init__(
        self,
        config: Config,
        parts: KioskParts,
        *,
        clock: Clock,
        store: Store | None,
        patient_ids: Callable[[], str] = new_patient_id,
    ) -> None:
        self.config, self.parts, self.clock, self.store = config, parts, clock, store
        self.patient_ids = patient_ids

        #: the battery of the latest visit (its next instrument comes from it)
        self.battery: Battery | None = None
        #: how well voice is heard in this kiosk's room, over all its patients (kiosk.core.room)
        self.room = RoomHearing()

    def _battery(
        self, visit_id: str | None = None, ids: Sequence[str] | None = None, *, walk_up: bool = False
    ) -> Battery:
        from qos import Engine

        policy, config, parts = self.parts.policy, self.config, self.parts
        self.battery = Battery(
            parts.battery(ids),
            make_engine=lambda name: Engine(parts.model_for(name)),
            shared={
                "clock": self.clock,
                "store": self.store,
                "timing": config.timing,
                "adaptation": Adaptation(policy) if policy else None,
                "next_patient_after_s": config.next_patient_after_s,
                "watching": Watching(config.away_alert_after_s, config.unattended_after),
                "room": self.room,
            },
            visit_id=visit_id,
            # a walk-up never has the Timed Up and Go: it needs staff beside the patient
            steps=[s for s in parts.visit_steps(ids) if not (walk_up and s == TUG)],
        )
        return self.battery

    def fresh(
        self,
        patient: str | None = None,
        language: str | None = None,
        answered_by: str = "patient",
        visit: str | None = None,
        instruments: Sequence[str] | None = None,
        **first: Any,
    ) -> Session:
        """The first instrument's session for ``patient`` (None: a walk-up with a new id);
        ``instruments``: an order's instruments (default: the configured battery); ``first``
        overrides the configuration for one session (``session_id``, ``familiarisation``)."""
        options = {"familiarisation": self.config.familiarisation, **first}
        walk_up = instruments is None and visit is None and patient is None
        if walk_up:  # never a caregiver's instrument
            instruments = walk_up_instruments([i.questionnaire for i in self.parts.battery()]) or None
        return self._battery(ids=instruments, walk_up=walk_up).first(
            patient_id=patient or self.patient_ids(),
            language=language or self.config.language,
            answered_by=answered_by,
            visit=visit or (STAFF if patient else WALK_UP),
            **options,
        )

    def after(self, session: Session) -> Session | None:
        """The session of the battery's next instrument after ``session`` (None: the visit is over)."""
        return self.battery.after(session) if self.battery is not None else None

    def resume(self, stored: StoredSession) -> Session:
        """The session continuing ``stored``, with the questionnaire it started with, whatever
        the file says now. Part of a battery, the visit goes on with its remaining instruments and
        the QoS trace of its earlier ones (found in the store)."""
        from kiosk.export.captured import questionnaire_of  # a continued test only: not before the welcome
        from qos import Engine

        questionnaire = questionnaire_of(stored, fallback=self.parts.questionnaire)
        place = Battery.place_of(stored)
        battery = self._battery(place.visit_id if place else None)
        if place is None or place.instruments != battery.ids or self.store is None:
            self.battery = None  # not a battery this kiosk gives (any more): this test alone, on the
            # QoS model this kiosk runs its instrument on (the kiosk's own for one it does not give)
            index = next((i for i, given in enumerate(battery.ids) if given == questionnaire.id), None)
            engine = battery.qos(index)[0] if index is not None else Engine(self.parts.model)
            return Session.from_stored(questionnaire, stored, engine=engine, **battery.shared)
        before = []
        for summary in self.store.sessions():
            if summary.patient_id == stored.patient_id and summary.id != stored.id:
                earlier = self.store.session(summary.id)
                found = Battery.place_of(earlier)
                if found is not None and found.visit_id == place.visit_id and found.index < place.index:
                    before.append((found.index, earlier))
        return battery.resume(stored, [earlier for _, earlier in sorted(before, key=lambda pair: pair[0])])


def make_kiosk(
    config: Config,
    *,
    clock: Clock,
    store: Store,
    channels: KioskChannels | None = None,
    parts: KioskParts | None = None,
    first: Mapping[str, Any] | None = None,
    patient_ids: Callable[[], str] = new_patient_id,
    poll_interval: float = POLL_INTERVAL,
    visits: bool = True,
    clinician_pin: str | PinGuard | None = None,
) -> KioskApp:
    """The kiosk ``config`` describes, on ``clock`` and ``store``, with ``channels`` (default:
    touch only). ``parts`` are loaded from ``config`` when not given (see :meth:`KioskParts.load`
    for the errors). ``first`` are :meth:`SessionMaker.fresh`'s arguments for the first session
    (``patient``: `kiosk run --patient`). ``visits=False`` leaves out the visits desk (every
    welcome a walk-up; staff cannot start a visit by identifier). ``clinician_pin`` replaces the
    configured PIN guard (a plain PIN: failures counted in memory, not in the data directory).
    With ``config.station`` the station's client and order watcher are wired, not started (the
    app starts them once the welcome is drawn)."""
    parts = parts or KioskParts.load(config)
    maker = SessionMaker(config, parts, clock=clock, store=store, patient_ids=patient_ids)
    sync, orders, start_order = _station(config, parts, store, lambda: app)
    controller = KioskController(
        maker.fresh(**(first or {})),
        store=store,
        fresh=maker.fresh,
        resume=maker.resume,
        after=maker.after,
        visits=VisitDesk(maker.fresh, walk_up=config.walk_up, id_pattern=config.patient_id_pattern) if visits else None,
        sync=sync,
        orders=orders,
        start_order=start_order,
        tugs=TugDesk(
            clock,
            store,
            battery=lambda: maker.battery,
            settings=lambda: tug_settings(config),
            camera=lambda: app.channels.camera_off(),
            poses=lambda: app.channels.poses,
            say=lambda key, language: app.channels.say(ui_text(language, key), language),
        ),
    )
    app = KioskApp(
        controller,
        channels,
        clinician_pin=clinician_pin or PinGuard(config.pin_secret, PinFiles(config.data_dir)),
        export_dir=config.data_dir / "exports",
        export_site=site_from_config(config),
        poll_interval=poll_interval,
        show_score=config.show_score_to_patient,
    )
    return app


def _station(config: Config, parts: KioskParts, store: Store, app: Callable[[], KioskApp]) -> tuple[Any, Any, Any]:
    """The ward station's client, the watcher of this kiosk's ordered visits and the call that
    starts one with its code; (None, None, None) without a station (staff then start visits on
    the clinician screen). Both report to the app from their own threads. The client and the
    watcher are built when the app starts them, after the welcome is drawn (:class:`LateStart`):
    their modules (``http.client``, the outbox) are not imported before it."""
    station = config.station
    if station is None:
        return None, None, None
    instruments, languages = parts.ids, parts.languages

    def client() -> Any:
        from kiosk.sync.client import SyncClient

        made = SyncClient(
            store.path,
            url=station.url,
            token=station.token,
            kiosk_id=station.kiosk_id,
            on_command=lambda command: app().station_command(command),
        )
        store.on_outbox = made.wake
        return made

    def watcher() -> Any:
        from kiosk.sync.http import Station
        from kiosk.sync.orders import OrderWatcher, held_orders

        return OrderWatcher(
            Station(station.url, station.token),
            instruments=instruments,
            languages=languages,
            on_orders=lambda *found: app().call_from_thread(app().controller.orders_changed, *found),
            held=lambda: held_orders(store.path),
            on_cancelled=lambda ids: app().call_from_thread(app().visit_cancelled, ids),
        )

    def start(code: str) -> Any:
        from kiosk.sync.http import Station
        from kiosk.sync.orders import start_order

        return start_order(Station(station.url, station.token), code, instruments=instruments, languages=languages)

    return LateStart(client), LateStart(watcher), start


class LateStart:
    """A station part (client or order watcher) built by ``make()`` when first started or asked
    for anything else; before that a status is held for it (the client sends it once started) and
    a stop stops nothing. The client delivers what the outbox holds as soon as it starts."""

    def __init__(self, make: Callable[[], Any]) -> None:
        self._make = make
        self._made: Any = None
        self._status: Any = None

    def _part(self) -> Any:
        if self._made is None:
            self._made = self._make()
            if self._status is not None:
                self._made.set_status(self._status)
        return self._made

    def start(self) -> None:
        self._part().start()

    def stop(self) -> None:
        if self._made is not None:
            self._made.stop()

    def set_status(self, status: Any) -> None:
        if self._made is None:
            self._status = status
        else:
            self._made.set_status(status)

    def wake(self, alert: bool = False) -> None:
        if self._made is not None:
            self._made.wake(alert)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._part(), name)
