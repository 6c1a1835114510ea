"""The one place a kiosk is put together: :func:`make_kiosk`.

`kiosk run` (:mod:`kiosk.commands.run`), the UI tests and the benches all build their kiosk here,
so what a test drives is what a ward runs: the same sessions for the next patient and for a
continued test, the same visits desk, the same station wiring. What differs is injected: the
clock (a :class:`~kiosk.core.clock.SimClock` in tests), the store, and the channels this machine
has (:class:`~kiosk.ui.channels.KioskChannels`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from kiosk.core.adaptation import Adaptation, Policy, load_policy
from kiosk.core.clock import Clock
from kiosk.core.pin import PinGuard
from kiosk.core.qos_model import load_kiosk_model
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.session import Session
from kiosk.core.visits import STAFF, WALK_UP, VisitDesk
from kiosk.export import site_from_config
from kiosk.export.captured import questionnaire_of
from kiosk.store.database import Store, StoredSession, new_patient_id
from kiosk.ui.app import POLL_INTERVAL, KioskApp
from kiosk.ui.channels import KioskChannels
from kiosk.ui.controller import KioskController

if TYPE_CHECKING:
    from kiosk.config import Config
    from qos import Model


@dataclass(frozen=True)
class KioskParts:
    """What a configuration names and every session shares: the questionnaire, the QoS model
    and the adaptation policy (None: adaptation off)."""

    questionnaire: Questionnaire
    model: Model
    policy: Policy | None

    @classmethod
    def load(cls, config: Config) -> KioskParts:
        """Load them; raises QuestionnaireError, ConfigError, ModelError or PolicyError (one
        sentence, with the file and where) for a bad file."""
        from kiosk.config import configured_questionnaire, offered_to_patients

        # a site offers patients only validated translations and those it accepts
        questionnaire = offered_to_patients(config, configured_questionnaire(config))
        model = load_kiosk_model(config.qos_model)
        policy = load_policy(config.adaptation_policy, model=model) if config.adaptation else None
        return cls(questionnaire, model, policy)


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

    def _shared(self) -> dict[str, Any]:
        from qos import Engine

        policy, config = self.parts.policy, self.config
        return {
            "clock": self.clock,
            "engine": Engine(self.parts.model),
            "store": self.store,
            "timing": config.timing,
            "adaptation": Adaptation(policy) if policy else None,
            "next_patient_after_s": config.next_patient_after_s,
        }

    def fresh(
        self,
        patient: str | None = None,
        language: str | None = None,
        answered_by: str = "patient",
        visit: str | None = None,
        **first: Any,
    ) -> Session:
        """A session for ``patient`` (None: a walk-up with a new id); ``first`` overrides the
        configuration for one session (``session_id``, ``familiarisation``)."""
        options = {"familiarisation": self.config.familiarisation, **first}
        return Session(
            self.parts.questionnaire,
            patient_id=patient or self.patient_ids(),
            language=language or self.config.language,
            answered_by=answered_by,
            visit=visit or (STAFF if patient else WALK_UP),
            **self._shared(),
            **options,
        )

    def resume(self, stored: StoredSession) -> Session:
        """The session continuing ``stored``, with the questionnaire it started with, whatever
        the file says now."""
        questionnaire = questionnaire_of(stored, fallback=self.parts.questionnaire)
        return Session.from_stored(questionnaire, stored, **self._shared())


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
    sync, orders, start_order = _station(config, parts.questionnaire, store, lambda: app)
    controller = KioskController(
        maker.fresh(**(first or {})),
        store=store,
        fresh=maker.fresh,
        resume=maker.resume,
        visits=VisitDesk(maker.fresh, walk_up=config.walk_up) if visits else None,
        sync=sync,
        orders=orders,
        start_order=start_order,
    )
    app = KioskApp(
        controller,
        channels,
        clinician_pin=clinician_pin or PinGuard(config.pin_secret, config.data_dir),
        export_dir=config.data_dir / "exports",
        export_site=site_from_config(config),
        poll_interval=poll_interval,
        show_score=config.show_score_to_patient,
    )
    return app


def _station(
    config: Config, questionnaire: Questionnaire, store: Store, app: Callable[[], KioskApp]
) -> tuple[Any, Any, Any]:
    """The ward station's client, the watcher of this kiosk's ordered visits and the call that
    starts one with its code; (None, None, None) without a station (staff then start visits on
    the clinician screen). Both report to the app from their own threads."""
    station = config.station
    if station is None:
        return None, None, None
    from kiosk.sync import SyncClient
    from kiosk.sync.http import Station
    from kiosk.sync.orders import OrderWatcher, start_order

    client = SyncClient(
        store.path,
        url=station.url,
        token=station.token,
        kiosk_id=station.kiosk_id,
        on_command=lambda command: app().station_command(command),
    )
    store.on_outbox = client.wake
    instruments, languages = [questionnaire.id], list(questionnaire.languages)
    watcher = OrderWatcher(
        Station(station.url, station.token),
        instruments=instruments,
        languages=languages,
        on_orders=lambda *found: app().call_from_thread(app().controller.orders_changed, *found),
    )
    starter = Station(station.url, station.token)
    return client, watcher, lambda code: start_order(starter, code, instruments=instruments, languages=languages)
