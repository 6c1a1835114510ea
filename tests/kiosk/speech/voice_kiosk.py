"""The real session on a simulated clock with a voice channel attached as the app does, and the
recognisers a voice test runs with; shared by the voice channel's tests."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from kiosk.core.channels import Channel, ChannelInput, ChannelStatus
from kiosk.core.clock import SimClock
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import ListeningChanged, Prompt, Session
from kiosk.speech.asr import PocketSphinxRecogniser, VoskRecogniser
from kiosk.speech.audio import feed_wav
from kiosk.speech.models import find_model
from kiosk.speech.voice import VoiceChannel

QUESTIONNAIRE = load_questionnaire()


def backends(language: str):
    params = []
    if language == "en":
        params.append(pytest.param(lambda lang: PocketSphinxRecogniser(lang), id="pocketsphinx"))
    # as the kiosk finds one; the sealed run clears KIOSK_VOSK_MODEL and the user's models folder,
    # so a developer names a model for the tests with TESTS_VOSK_MODEL (tests/conftest.py)
    model = find_model(language, os.environ.get("TESTS_VOSK_MODEL") or None)
    params.append(
        pytest.param(
            lambda lang, model=model: VoskRecogniser(model, lang),
            id="vosk",
            marks=pytest.mark.skipif(
                model is None,
                reason=f"no vosk model for {language!r}: set TESTS_VOSK_MODEL to one (none can be downloaded here)",
            ),
        )
    )
    return params


class VoiceKiosk:
    """The real session on a simulated clock, with a voice channel attached the way the app does."""

    def __init__(self, recogniser_factory, language: str = "en", app_style: bool = False, microphone=None) -> None:
        self.clock = SimClock()
        self.session = Session(
            QUESTIONNAIRE, clock=self.clock, engine=None, patient_id="P-0042", language=language, familiarisation=False
        )
        self.events: list[object] = []
        self.statuses: list[ChannelStatus] = []
        self.unmatched: list[tuple[str, str]] = []
        #: every answer or command the voice channel sent
        self.inputs: list[ChannelInput] = []
        self.voice = VoiceChannel(
            language,
            recogniser_factory=recogniser_factory,
            on_unmatched=lambda u, r: self.unmatched.append((u, r)),
            **({"microphone_factory": microphone} if microphone else {}),
        )
        self.session.subscribe(self.events.append)
        self.session.subscribe(self._app_forward if app_style else self.voice.on_session_event)
        if microphone is None:
            self.available = self.voice.attach(self._sink)
        else:
            self.voice.start(self._sink)

    def _app_forward(self, event: object) -> None:
        """What kiosk.ui.app does with session events for voice in."""
        if isinstance(event, Prompt):
            self.voice.expect(event)
        elif isinstance(event, ListeningChanged):
            self.voice.listen(event.listening)

    def _sink(self, item: ChannelInput | ChannelStatus) -> None:
        # the app's sink hops to the UI thread; here the test thread is that thread
        if isinstance(item, ChannelStatus):
            self.statuses.append(item)
        else:
            self.inputs.append(item)
            self.session.handle(item)

    def to_question(self, item_id: str) -> None:
        self.session.start()
        self.session.acknowledge()
        while (
            self.session.current_item is None or self.session.current_item.id != item_id or not self.session.listening
        ):
            if self.session.current_item is not None and self.session.listening:
                self.session.handle(ChannelInput(Channel.TOUCH, option=1))
            self.clock.advance(0.5)
            self.session.poll()

    def say(self, wav: Path) -> None:
        feed_wav(wav, self.voice)

    def answer(self, wav: Path, spoken) -> None:
        """Say an answer, and "yes" when the kiosk asks back "I heard ... Is that right?"."""
        self.say(wav)
        prompts = [e for e in self.events if isinstance(e, Prompt)]
        if prompts and prompts[-1].kind == "confirm":
            language = prompts[-1].language
            self.say(spoken({"en": "yes", "es": "sí", "fr": "oui"}[language], language))
