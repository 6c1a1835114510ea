"""`kiosk run` (also plain `kiosk`): the kiosk as configured, with whatever channels this machine has.

This module reads the configuration, opens the store and finds the channels (remotes, espeak-ng,
a microphone); :func:`kiosk.ui.compose.make_kiosk` puts the kiosk together, as it does for the
UI tests. A user's mistake (a bad configuration, questionnaire, data directory or profile file)
is one sentence and exit status 2.
"""

from __future__ import annotations

import dataclasses
import gc
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from basis.errors import KioskError
from kiosk.core.channels import Channel, ChannelState, ChannelStatus, InputSource, Sink
from kiosk.ui.options import run_parser

if TYPE_CHECKING:
    from kiosk.config import Config
    from kiosk.store.database import Store
    from kiosk.store.migrations import InForce
    from kiosk.ui.app import KioskApp


class SetupError(KioskError):
    """The kiosk cannot start: a bad configuration, questionnaire, data directory or profile file."""


def build_app(
    *,
    config_path: Path | None = None,
    data_dir: Path | None = None,
    patient_id: str | None = None,
    voice: bool = True,
    remote: bool = True,
) -> tuple[KioskApp, Callable[[], None]]:
    """The kiosk as configured, with whatever channels this machine has, and a function that
    closes what it opened. Raises :class:`SetupError` (one sentence) for a user's mistake."""
    from kiosk.config import ConfigError, load_config, site_from_config
    from kiosk.core.adaptation import PolicyError
    from kiosk.core.clock import SystemClock
    from kiosk.core.questionnaire import QuestionnaireError
    from kiosk.core.site import export_identity
    from kiosk.store.database import PATIENT_ID, StorageError, Store
    from kiosk.ui.channels import KioskChannels
    from kiosk.ui.compose import KioskParts, make_kiosk
    from qos import ModelError

    if patient_id is not None and not PATIENT_ID.match(patient_id):
        raise SetupError(
            f"--patient {patient_id!r} is not a pseudonymous id: use letters, digits, '-' "
            "and '_' only (2 to 64 characters), never a name"
        )
    try:
        config = load_config(config_path)
        if data_dir is not None:
            config = dataclasses.replace(config, data_dir=data_dir)
        parts = KioskParts.load(config)
        store = Store.open(
            config.data_dir,
            interrupt_after_s=config.interrupt_after_minutes * 60,
            outbox=config.station is not None,
            export=export_identity(site_from_config(config)),
            in_force=lambda: _in_force(config),
        )
    except QuestionnaireError as error:
        problems = getattr(error, "problems", None)
        raise SetupError("\n".join(str(p) for p in problems) if problems else str(error)) from None
    except (ConfigError, PolicyError, ModelError, StorageError) as error:
        raise SetupError(str(error)) from None
    statuses: list[ChannelStatus] = []
    keyboard, sources = _remotes(config.remote_profiles, remote, statuses, store)
    camera = _LateCamera()
    sources.append(camera)
    channels = KioskChannels(
        poses=camera,
        speaker=_speaker() if voice else None,
        voice=_voice_in(config, voice, statuses),
        sources=sources,
        keyboard=keyboard,
        statuses=statuses,
    )
    app = make_kiosk(
        config, clock=SystemClock(), store=store, channels=channels, parts=parts, first={"patient": patient_id}
    )
    # what a kiosk that stopped left running is interrupted now (after the station's client is
    # wired, so it hears of them): for staff, never a patient
    store.interrupt_stale()
    return app, store.close


def _in_force(config: Config) -> InForce:
    """What an upgrade of an older database attaches to its sessions (only then are the exports'
    modules needed)."""
    from kiosk.export.opening import in_force_of

    return in_force_of(config)


class _LateCamera:
    """The camera channel, looked for only when the app starts its channels (after the first frame):
    nothing of :mod:`kiosk.camera` loads before the welcome. Without a camera or the pose model it
    reports the camera off with why, and the kiosk runs as without it. Its landmarks go to a
    :class:`~kiosk.camera.feed.PoseFeed` a visit's Timed Up and Go drains (``into``, ``clear``)."""

    name = "camera"

    def __init__(self) -> None:
        self._channel: Any = None
        self._stopped = False
        self._feed: Any = None

    def into(self, step: Any, before: float | None = None) -> int:
        return self._feed.into(step, before) if self._feed is not None else 0

    def clear(self) -> None:
        if self._feed is not None:
            self._feed.clear()

    def start(self, sink: Sink) -> None:
        from kiosk.camera import camera_channel, camera_status, presence_reports
        from kiosk.camera.feed import PoseFeed

        status = camera_status()
        sink(status)
        if status.state is not ChannelState.OFF and not self._stopped:
            self._feed = PoseFeed()
            self._channel = camera_channel(on_pose=self._feed, on_presence=presence_reports(sink))
            if self._channel is not None:
                self._channel.start(sink)

    def stop(self) -> None:
        self._stopped = True
        if self._channel is not None:
            self._channel.stop()


def _remotes(
    profiles: Path | None, wanted: bool, statuses: list[ChannelStatus], store: Store
) -> tuple[Any, list[InputSource]]:
    """The keyboard-remote key map and the serial/HID sources, or the reason there are none."""
    if not wanted:
        statuses.append(ChannelStatus(Channel.REMOTE, ChannelState.OFF, "remote", "turned off (--no-remote)"))
        return None, []
    from kiosk.remote import ProfileError, keyboard_remote, open_sources

    try:
        return keyboard_remote(profiles), open_sources(profiles)
    except ProfileError as error:
        store.close()
        raise SetupError(str(error)) from None


def _speaker() -> Any:
    """espeak-ng voice out; it reports on or off (with the reason) once its worker has looked."""
    from kiosk.speech.tts import Speaker

    return Speaker()


def _voice_in(config: Any, wanted: bool, statuses: list[ChannelStatus]) -> Any:
    """The voice-in channel (it reports on, or off with the reason, once started), or None."""
    if not wanted:
        statuses.append(ChannelStatus(Channel.VOICE, ChannelState.OFF, "voice in", "turned off (--no-voice)"))
        return None
    from kiosk.speech.voice import VoiceChannel

    return VoiceChannel(config.language, vosk_model=config.vosk_model)


def _collect_from_now_on() -> None:
    """The welcome is drawn: what the start made is kept out of the collector's walks for good
    (:func:`gc.freeze`), and collecting resumes."""
    gc.freeze()
    gc.enable()


def main(argv: list[str]) -> int:
    """`kiosk run`: build the session and channels from the configuration and run the app."""
    args = run_parser().parse_args(argv)
    # Every object the start makes (classes, words, questionnaire, stylesheet) stays alive, yet the
    # cyclic collector would walk them over and over while the patient waits: about a tenth of the
    # start (bench/startup.py). Paused until the welcome is drawn; then they are frozen out of its
    # reach, so later collections do not walk them either.
    gc.disable()
    try:
        app, close = build_app(
            config_path=args.config,
            data_dir=args.data_dir,
            patient_id=args.patient,
            voice=not args.no_voice,
            remote=not args.no_remote,
        )
    except SetupError as error:
        gc.enable()
        print(f"kiosk run: {error}", file=sys.stderr)
        return 2
    app.after_first_frame.append(_collect_from_now_on)
    if (warning := app.pin_guard.warning) is not None:
        print(f"kiosk run: warning: {warning}", file=sys.stderr)
    try:
        app.run()
    finally:
        close()
    return app.return_code or 0
