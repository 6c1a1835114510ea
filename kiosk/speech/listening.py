"""What voice in listens for on the current prompt, and what a heard utterance means there.

:class:`Listening` holds the prompt's state (its options, whether they score, whether they reply to
"Is that right?", the welcome, the thank-you gap, a pause, the options declined on this question)
and turns it into the recogniser's grammar and each utterance into a :class:`ChannelInput` or the
reason it is none. Plain state, no threads and no audio: :class:`kiosk.speech.voice.VoiceChannel`
calls it under its own lock, and it is tested without a microphone.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, cast

from kiosk.core.channels import Channel, ChannelInput
from kiosk.speech.matching import (
    NEGATIONS,
    Match,
    Matcher,
    OptionWords,
    heard_negation,
    undo_commands,
    welcome_commands,
)

if TYPE_CHECKING:  # the audio pipeline (numpy) loads on the channel's own threads
    from kiosk.speech.asr import Recognition
    from kiosk.speech.audio import Utterance

#: the voice channel's own log: what was heard and why it was not taken
log = logging.getLogger("kiosk.speech.voice")

#: a spoken "yes" to "Is that right?" is taken as said only this sure, or heard twice (a "no"
#: declines at the matcher's own floor): on voices and rooms the kiosk had never heard, "no no" and
#: "that's not what I said" were heard as "yes" at 0.64-0.65 and stored two wrong answers (issue 33)
YES_MIN_CONFIDENCE = 0.8

#: an answer heard with less than the matcher's minimum confidence, but at least this, twice in a
#: row on the same question (the attempt and the patient's repeat), is asked back: two hearings
#: that agree are worth an "Is that right?", and short answers were otherwise lost; it is never
#: stored without the patient's yes (docs/speech-tuning.md)
AGREE_MIN_CONFIDENCE = 0.2


class Listening:
    """The current prompt as voice in hears it. Not thread-safe: its owner serialises calls."""

    def __init__(self, *, min_confidence: float, confirm_below: float, reply_min_above_room_db: float) -> None:
        self.min_confidence = min_confidence
        #: a scored answer heard with a confidence below this is sent with needs_confirmation
        self.confirm_below = confirm_below
        #: a reply to "Is that right?" spoken less far above the room than this is sent as unsure
        self.reply_min_above_room_db = reply_min_above_room_db
        #: whether the current prompt asks "Is that right?" (a reply stores an answer)
        self.confirming = False
        #: whether the current options score points (a Barthel question): only those answers
        #: are ever confirmed; a confirmation's own yes/no or a language choice is not
        self.scored = False
        #: the prompt comes before the test (the welcome, the explanation's Start): only "call the
        #: doctor" besides its options (:func:`kiosk.speech.matching.welcome_commands`)
        self.welcome = False
        #: an answer was just stored: only "No, that's wrong" (and the doctor) until the next prompt
        self.undo_only = False
        #: the session is paused: only commands are listened for, so "continue" works
        self.paused = False
        self.options: list[OptionWords] = []
        #: the matcher of the grammar last built (None: nothing to listen for yet)
        self.matcher: Matcher | None = None
        #: options the patient declined ("Is that right?" No) on the question ``_declined_on``
        self._declined: set[int] = set()
        self._declined_on: str | None = None
        #: the option the latest utterance on this scored question was unsure of (see
        #: :data:`AGREE_MIN_CONFIDENCE`)
        self._unsure: int | None = None
        #: a "yes" was heard once already on this "Is that right?", not sure enough to take
        #: alone: a second "yes" on it is the second hearing
        self._yes_once = False
        self._key: str | None = None

    # -- the prompt --------------------------------------------------------------------------

    def set_question(
        self,
        options: Sequence[OptionWords],
        *,
        scored: bool,
        welcome: bool,
        key: str | None,
        confirming: bool,
        again: bool = False,
    ) -> None:
        """A new prompt's options (see :meth:`kiosk.speech.voice.VoiceChannel.set_question`);
        ``again``: the same prompt asked again ("Please press Yes or No")."""
        if scored:
            self._on_question(key)
        if not (confirming and again and key == self._key):
            self._yes_once = False  # a second hearing agrees with a first on the same confirmation only
        self._key = key
        self.options = list(options)
        self.scored = scored
        self.welcome = welcome
        self.confirming = confirming
        self.undo_only = False

    def declined(self, key: str, option: int) -> None:
        """The patient said No to ``option`` on question ``key``: left out of its grammar while it
        is asked again, so the recogniser does not offer the same mishearing twice."""
        self._on_question(key)
        self._declined.add(option)
        self._unsure = None

    def _on_question(self, key: str | None) -> None:
        """What was declined or heard unsure belongs to one question: another one (or one
        without a name) starts afresh."""
        if key is None or key != self._declined_on:
            self._declined_on, self._declined, self._unsure = key, set(), None

    def expect_undo(self) -> None:
        """An answer was stored: only taking it back and calling the doctor until the next prompt."""
        self.options = []
        self.scored = self.confirming = False
        self.welcome = False
        self.undo_only = True

    def set_paused(self, paused: bool) -> bool:
        """The session paused or resumed; whether that changed anything."""
        if paused == self.paused:
            return False
        self.paused = paused
        return True

    # -- the grammar -------------------------------------------------------------------------

    def grammar(self, language: str) -> list[str] | None:
        """Build :attr:`matcher` for ``language`` and return the phrases to listen for; None while
        there is nothing to listen for (no prompt with options yet)."""
        if not (self.options or self.paused or self.undo_only):
            return None
        options = [] if self.paused else self.options
        commands = None  # all of them: a question, or only commands while paused
        if self.welcome and not self.paused:
            commands = welcome_commands(language)
        elif self.undo_only and not self.paused:
            commands = undo_commands(language)
        before_test = self.welcome and not self.paused  # a language or Start is said in words
        self.matcher = Matcher(
            options, language, self.min_confidence, paused=self.paused, commands=commands, numbers=not before_test
        )
        phrases = self.matcher.phrases()
        if self.scored and not self.paused and self._declined:
            phrases = [p for p in phrases if self.matcher.meaning(p) not in self._declined]
        return phrases

    @property
    def taken_as_heard(self) -> bool:
        """Whether an option heard under the current grammar is acted on without being asked back:
        a scored question's answers are all asked back unless the channel takes sure ones as heard."""
        return not (self.scored and self.confirm_below > 1)

    # -- an utterance ------------------------------------------------------------------------

    def hear(self, utterance: Utterance) -> ChannelInput | str:
        """What the utterance means on this prompt: the input for the session, or why it is none."""
        result = cast("Recognition", utterance.result)
        if self.matcher is None:  # the grammar was taken away while this was being heard
            return "heard after the grammar was taken away"
        match = self.matcher.match(result.text, result.confidence)
        if not match.matched:
            match = self._heard_twice(result) or match
        if not match.matched:
            return match.reason
        if result.confusable and match.option is not None and not self.scored:
            # "the first one" heard where "the third one" means something else, and nothing to
            # ask back with (only a scored question's answers are confirmed): asked again
            return f"{result.text!r} is confusable with another answer and cannot be confirmed here"
        # a scored answer below confirm_below is asked back, and always a confusable phrase or
        # one heard twice unsure
        unsure = result.confusable or result.confidence < max(self.min_confidence, self.confirm_below)
        confirm = self.scored and match.option is not None and unsure
        if self.confirming and match.option is not None and self._too_loud(utterance):
            confirm = True
        if self.confirming and match.option == 1 and not confirm:
            doubt = self._yes_doubt(result)
            if doubt:
                log.info("voice: %r taken as an unsure yes: %s", result.text, doubt)
                confirm = True
        elif self.confirming and match.option is not None:
            self._yes_once = False  # a "no" between two hearings of "yes": they do not agree
        self._unsure = None
        return ChannelInput(
            Channel.VOICE,
            option=match.option,
            command=match.command,
            detail=result.text,
            confidence=round(result.confidence, 3),
            needs_confirmation=confirm,
        )

    def _yes_doubt(self, result: Any) -> str:
        """Why a "yes" to "Is that right?" is not taken as said (empty: it is).

        Layered, each enough alone: a free transcript (a recogniser that also hears without the
        grammar fills ``transcript``) holding a negation, or not meaning "yes" itself (two
        hearings that do not agree); or the "yes" heard once below :data:`YES_MIN_CONFIDENCE`,
        which waits for a second hearing (the patient says it again, or presses Yes).
        """
        assert self.matcher is not None  # called from hear(), which has one
        language = self.matcher.language
        transcript = getattr(result, "transcript", None)
        for heard in (result.text, transcript):
            if heard and heard_negation(heard, language):
                self._yes_once = False
                return f"{heard!r} holds a negation ({', '.join(NEGATIONS[language][:3])}, ...)"
        if transcript is not None and self.matcher.match(transcript).option != 1:
            return f"the free hearing {transcript!r} is not a yes"
        if result.confidence >= YES_MIN_CONFIDENCE:
            return ""
        if self._yes_once:
            self._yes_once = False
            return ""  # heard twice on this "Is that right?": two hearings agree
        self._yes_once = True
        return f"heard once at {result.confidence:.2f} < {YES_MIN_CONFIDENCE:.2f}: a second hearing or a press"

    def _too_loud(self, utterance: Utterance) -> bool:
        """Whether the room was nearly as loud as the voice (see :attr:`reply_min_above_room_db`)."""
        above = utterance.above_room_db
        if above is None or above >= self.reply_min_above_room_db:
            return False
        heard = cast("Recognition", utterance.result).text
        log.info("voice: %r spoken %.1f dB above the room, too little to take as said", heard, above)
        return True

    def _heard_twice(self, result: Any) -> Match | None:
        """An unsure recognition that selects the same option as the one just before it on the
        same scored question, both at least :data:`AGREE_MIN_CONFIDENCE` sure: its match."""
        if not self.scored or self.paused:
            return None
        assert self.matcher is not None  # called from hear(), which has one
        match = self.matcher.match(result.text)
        unsure = match.option if result.confidence >= AGREE_MIN_CONFIDENCE else None
        agreed = unsure is not None and unsure == self._unsure
        self._unsure = None if agreed else unsure
        return match if agreed else None
