"""What the session shows and says: phases, prompts (questions, messages, the welcome, the
explanation, "Is that right?") and whether voice answers are wanted.

Every prompt is published to listeners and kept as the latest, so a screen rebuilt later shows
what was last said."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from kiosk.core.session.events import ListeningChanged, Phase, PhaseChanged, Prompt, PromptOption
from kiosk.core.session.publishing import Outputs
from kiosk.core.session.state import SessionState
from kiosk.core.session.timers import AttemptClock
from kiosk.core.session.words import (
    CONFIRM_WORDS,
    CONTINUE_LABEL,
    GO_ON_LABEL,
    LANGUAGE_NAMES,
    OWN_NAME,
    REST_TEXT,
    START_LABEL,
    START_WORDS,
    UNATTENDED_TEXT,
)
from kiosk.core.words import fill


class Prompts:
    """Publishes phases and prompts in the patient's language, and the listening state."""

    def __init__(self, state: SessionState, timers: AttemptClock, out: Outputs) -> None:
        self.state = state
        self.timers = timers
        self.out = out

    def set_phase(self, t: float, phase: Phase) -> None:
        state = self.state
        previous, state.phase = state.phase, phase
        self.out.emit(PhaseChanged(t, phase, previous))

    def message(self, t: float, name: str) -> None:
        """Publish the questionnaire's message ``name`` (nothing if it has none in this language)."""
        state = self.state
        text = state.questionnaire.message(name, state.language)
        if text:
            self.publish(Prompt(t, "message", name, text, text, state.language, speech_rate=state.speech_rate()))

    def ask(self, t: float, repeat: bool) -> None:
        """Ask the open question (or, while an answer waits for confirmation, "Is that right?")."""
        state = self.state
        assert state.open is not None
        if state.call is not None and state.call.prompt is not None:  # "Shall I call the nurse?" waits
            self.out.emit(replace(state.call.prompt, t=t, repeat=True))
            return
        if state.open.unconfirmed is not None:
            self.publish(self._confirmation(t, repeat))
            return
        lang = state.language
        question = state.question()
        options = tuple(
            PromptOption(o.number, o.label_in(lang), o.synonyms_in(lang), o.points) for o in question.options
        )
        spoken = question.spoken[lang]
        if repeat and state.questionnaire.message("repeat", lang):
            spoken = f"{state.questionnaire.message('repeat', lang)} {spoken}"
        self.publish(
            Prompt(
                t,
                "practice" if state.open.practice else "question",
                question.id,
                question.text[lang],
                spoken,
                lang,
                options,
                repeat,
                state.open.attempt,
                state.speech_rate(),
            )
        )

    def publish(self, prompt: Prompt) -> None:
        self.state.prompt = prompt
        self.out.emit(prompt)

    def update_listening(self, t: float) -> None:
        # on the welcome once it was shown (say a language), under the explanation (say "I'm
        # ready"), while an attempt is open, and in the thank-you gap after an answer, when it can
        # be taken back ("No, that's wrong")
        state = self.state
        wanted = (
            (state.phase is Phase.WELCOME and state.greeted)
            or state.phase in (Phase.EXPLANATION, Phase.REST)
            or state.current_attempt is not None
            or state.can_undo(self.timers.kind)
            or state.call is not None  # "Shall I call the nurse?" is answered by voice too
        )
        listening = wanted and not self.timers.frozen and not state.voice_off()
        if listening != state.listening:
            state.listening = listening
            self.out.emit(ListeningChanged(t, listening))

    def welcome(self, t: float) -> Prompt:
        """The welcome message with one option per language: its own name, what it is called in
        the prompt's language, and (for the language shown) the words for "start"."""
        state = self.state
        lang = state.language
        text = state.questionnaire.message("welcome", lang)
        options = tuple(
            PromptOption(
                number,
                OWN_NAME.get(language, language),
                (
                    *LANGUAGE_NAMES.get(lang, {}).get(language, ()),
                    *(START_WORDS.get(lang, ()) if language == lang else ()),
                ),
                None,
            )
            for number, language in enumerate(state.questionnaire.languages, start=1)
        )
        return Prompt(t, "welcome", "welcome", text, text, lang, options, speech_rate=state.speech_rate())

    def explanation(self, t: float) -> Prompt:
        """The explanation, with one option: Start, and the words for it ("I'm ready"), which the
        voice channel listens for while it is on screen."""
        state = self.state
        lang = state.language
        text = state.questionnaire.message("explanation", lang)
        options = (PromptOption(1, START_LABEL.get(lang, "Start"), tuple(START_WORDS.get(lang, ())), None),)
        return Prompt(t, "message", "explanation", text, text, lang, options, speech_rate=state.speech_rate())

    def rest(self, t: float) -> Prompt:
        """The rest screen before a battery's next instrument ("Well done. Next: <title>. Take a
        breath."), with one option: Continue (and the words for "start")."""
        state = self.state
        lang = state.language
        title = state.questionnaire.title.get(lang) or state.questionnaire.id
        text = fill(REST_TEXT.get(lang, REST_TEXT["en"]), title=title)
        label = CONTINUE_LABEL.get(lang, CONTINUE_LABEL["en"])
        options = (PromptOption(1, label, tuple(START_WORDS.get(lang, ())), None),)
        return Prompt(t, "message", "rest", text, text, lang, options, speech_rate=state.speech_rate())

    def unattended(self, t: float) -> None:
        """Publish the wait for a touch after questions in a row went unanswered ("Are you still
        there? Touch the screen to go on."), with one option: Go on. Nothing is listened for."""
        state = self.state
        lang = state.language
        text = UNATTENDED_TEXT.get(lang, UNATTENDED_TEXT["en"])
        options = (PromptOption(1, GO_ON_LABEL.get(lang, GO_ON_LABEL["en"]), (), None),)
        self.publish(Prompt(t, "message", "unattended", text, text, lang, options, speech_rate=state.speech_rate()))

    def to_explanation(self, t: float) -> None:
        """Go on to the explanation (after the practice questions, or at once)."""
        self.set_phase(t, Phase.EXPLANATION)
        self.publish(self.explanation(t))
        self.update_listening(t)

    def _confirmation(self, t: float, repeat: bool) -> Prompt:
        """ "I heard: <option>. Is that right?" with the options Yes and No, in the patient's language."""
        state = self.state
        open_ = state.open
        assert open_ is not None and open_.unconfirmed is not None
        lang = state.language
        item = state.questionnaire.items[open_.index]
        heard = item.option(open_.unconfirmed.option).label_in(lang)
        template = (
            (open_.unconfirmed.press and state.questionnaire.message("confirm_answer_press", lang))
            or state.questionnaire.message("confirm_answer", lang)
            or "{answer}?"
        )
        text = template.replace("{answer}", heard)
        words: Mapping[int, tuple[str, tuple[str, ...]]] = CONFIRM_WORDS.get(lang, CONFIRM_WORDS["en"])
        options = tuple(PromptOption(number, label, synonyms, None) for number, (label, synonyms) in words.items())
        return Prompt(t, "confirm", item.id, text, text, lang, options, repeat, open_.attempt, state.speech_rate())
