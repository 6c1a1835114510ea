"""A real kiosk for UI tests: the real session core, QoS engine, adaptation and SQLite store, on a
simulated clock that only moves when a test advances it. No channel threads are started; tests
deliver remote and voice inputs through the app's sink from a real thread, as the channels do."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from kiosk.core.adaptation import Adaptation, load_policy
from kiosk.core.channels import Channel, ChannelState, ChannelStatus
from kiosk.core.clock import SimClock
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import Session
from kiosk.export.opening import MODEL
from kiosk.store.database import Store
from kiosk.ui.app import KioskApp
from qos import Engine, load_model

#: the PIN the test kiosks use (not the public default, so no warning on the clinician screen)
UI_PIN = "2468"
#: fixed ids so snapshots do not change from run to run
UI_SESSION_ID = "5e55a0000001"
UI_PATIENT_ID = "P-TEST01"


class UiKiosk:
    """A kiosk app with its clock and store, and helpers to move simulated time."""

    def __init__(
        self,
        tmp_path: Path,
        *,
        familiarisation: bool = True,
        adaptation: bool = True,
        language: str = "en",
        session_id: str = UI_SESSION_ID,
        voice=None,
        keyboard=None,
        sources=(),
        poll_interval: float = 3600,
        speaker=None,
        show_score: bool = False,
        next_patient_after_s: float | None = None,
        model: str = MODEL,
        questionnaire: str | Path | None = None,
    ) -> None:
        self.next_patient_after_s = next_patient_after_s
        self.clock = SimClock()
        #: the QoS model (``qos_model:``), loaded once as `kiosk run` does
        self.model = load_model(model)
        #: the instrument (a file; None: the bundled Barthel)
        self.questionnaire = load_questionnaire(questionnaire)
        self.store = Store.open(tmp_path / "data")
        self.session = Session(
            self.questionnaire,
            clock=self.clock,
            engine=Engine(self.model),
            patient_id=UI_PATIENT_ID,
            store=self.store,
            language=language,
            session_id=session_id,
            adaptation=Adaptation(load_policy()) if adaptation else None,
            familiarisation=familiarisation,
            next_patient_after_s=next_patient_after_s,
        )
        self.app = KioskApp(
            self.session,
            clinician_pin=UI_PIN,
            store=self.store,
            export_dir=tmp_path / "exports",
            voice=voice,
            keyboard=keyboard,
            sources=sources,
            speaker=speaker,
            statuses=[
                ChannelStatus(Channel.VOICE, ChannelState.OFF, "voice in", "no microphone found"),
                ChannelStatus(Channel.REMOTE, ChannelState.OFF, "serial", "no serial remote on /dev/ttyUSB*"),
            ],
            # by default tests drive time themselves (the timer's callback, `advance`), so a tick
            # of the real timer never finds anything due
            poll_interval=poll_interval,
            resume=self._resume,
            new_session=self._fresh,
            show_score=show_score,
        )

    def _fresh(self) -> Session:
        """A session for the next patient, as `kiosk run` builds it (a new id, so it can be stored)."""
        return Session(
            self.questionnaire,
            clock=self.clock,
            engine=Engine(self.model),
            patient_id="P-TEST02",
            store=self.store,
            adaptation=Adaptation(load_policy()),
            next_patient_after_s=self.next_patient_after_s,
        )

    def _resume(self, stored) -> Session:
        """The session continuing ``stored``, as `kiosk run` builds it."""
        return Session.from_stored(
            self.questionnaire,
            stored,
            clock=self.clock,
            engine=Engine(self.model),
            store=self.store,
            adaptation=Adaptation(load_policy()),
        )

    def advance(self, seconds: float) -> None:
        """Move simulated time on and let the app poll, as its timer would."""
        self.clock.advance(seconds)
        self.app.poll_session()

    def to_next_deadline(self) -> None:
        """Jump to the session's next time-out and let the app poll."""
        self.to_next_deadline_of(self.session)

    def to_next_deadline_of(self, session: Session) -> None:
        """The same for ``session`` (the app's session after it continued an interrupted one)."""
        deadline = session.next_deadline()
        assert deadline is not None, "nothing is pending"
        self.clock.set(deadline)
        self.app.poll_session()


@pytest.fixture
def ui_kiosk(tmp_path: Path) -> Callable[..., UiKiosk]:
    """Build a :class:`UiKiosk` (keyword options: familiarisation, adaptation, language, session_id,
    offer_resume, voice, keyboard, sources, poll_interval, speaker, model, questionnaire)."""
    made: list[UiKiosk] = []

    def make(**options: object) -> UiKiosk:
        kiosk = UiKiosk(tmp_path, **options)  # type: ignore[arg-type]
        made.append(kiosk)
        return kiosk

    yield make
    for kiosk in made:
        kiosk.store.close()
