"""A real kiosk for UI tests: the real session core, QoS engine, adaptation and SQLite store, on a
simulated clock that only moves when a test advances it. No channel threads are started; tests
deliver remote and voice inputs through the app's sink from a real thread, as the channels do."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from kiosk.config import Config
from kiosk.core.channels import Channel, ChannelState, ChannelStatus
from kiosk.core.clock import SimClock
from kiosk.core.session import Session
from kiosk.export.opening import MODEL
from kiosk.store.database import Store
from kiosk.ui.channels import KioskChannels
from kiosk.ui.compose import KioskParts, make_kiosk

#: the PIN the test kiosks use (not the public default, so no warning on the clinician screen)
UI_PIN = "2468"
#: fixed ids so snapshots do not change from run to run
UI_SESSION_ID = "5e55a0000001"
UI_PATIENT_ID = "P-TEST01"


class UiKiosk:
    """A kiosk app built by `kiosk run`'s own :func:`make_kiosk`, with its clock and store, and
    helpers to move simulated time. The options other than the first session's (``familiarisation``,
    ``language``, ``session_id``) are the configuration's, so they hold for every later session;
    the next patients are P-TEST02 (the first is :data:`UI_PATIENT_ID`). ``pin_on_disk``: the PIN
    guard the kiosk builds itself, counting failures in the data directory (else in memory)."""

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
        pin_on_disk: bool = False,
        instruments: tuple = (),
        unattended_after: int | None = None,
        away_alert_after_s: float | None = 60.0,
        visits: bool = False,
    ) -> None:
        self.clock = SimClock()
        self.config = Config(
            data_dir=tmp_path / "data",
            adaptation=adaptation,
            qos_model=model,  # loaded once, as `kiosk run` does
            questionnaire=Path(questionnaire) if questionnaire is not None else None,
            next_patient_after_s=next_patient_after_s,
            show_score_to_patient=show_score,
            **({"clinician_pin": UI_PIN} if pin_on_disk else {}),
            instruments=instruments,  # a battery (kiosk.config.InstrumentChoice), else the Barthel
            # None: every question may time out and the kiosk asks on (the tests from before issue 36)
            unattended_after=unattended_after,
            away_alert_after_s=away_alert_after_s,
        )
        parts = KioskParts.load(self.config)
        self.questionnaire, self.model = parts.questionnaire, parts.model
        self.store = Store.open(self.config.data_dir)
        patients = iter([UI_PATIENT_ID])
        channels = KioskChannels(
            speaker=speaker,
            voice=voice,
            sources=sources,
            keyboard=keyboard,
            statuses=[
                ChannelStatus(Channel.VOICE, ChannelState.OFF, "voice in", "no microphone found"),
                ChannelStatus(Channel.REMOTE, ChannelState.OFF, "serial", "no serial remote on /dev/ttyUSB*"),
            ],
        )
        self.app = make_kiosk(
            self.config,
            clock=self.clock,
            store=self.store,
            channels=channels,
            parts=parts,
            first={"language": language, "session_id": session_id, "familiarisation": familiarisation},
            patient_ids=lambda: next(patients, "P-TEST02"),
            # by default tests drive time themselves (the timer's callback, `advance`), so a tick
            # of the real timer never finds anything due
            poll_interval=poll_interval,
            # off by default: the snapshots show "Start a visit" off, as before visits existed
            visits=visits,
            # failed attempts counted in memory, or (pin_on_disk) the kiosk's own guard, counting
            # them in the data directory
            clinician_pin=None if pin_on_disk else UI_PIN,
        )
        #: the kiosk's controller, and its first session
        self.controller = self.app.controller
        self.session: Session = self.app.session
        #: where the clinician's exports go
        self.exports = self.config.data_dir / "exports"

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
def ui_kiosk(tmp_path: Path) -> Iterator[Callable[..., UiKiosk]]:
    """Build a :class:`UiKiosk` (keyword options: familiarisation, adaptation, language, session_id,
    voice, keyboard, sources, poll_interval, speaker, show_score, next_patient_after_s, model,
    questionnaire, pin_on_disk, instruments, unattended_after, away_alert_after_s, visits)."""
    made: list[UiKiosk] = []

    def make(**options: Any) -> UiKiosk:
        kiosk = UiKiosk(tmp_path, **options)
        made.append(kiosk)
        return kiosk

    yield make
    for kiosk in made:
        kiosk.store.close()
