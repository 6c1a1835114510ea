"""What the patient said → an answer option or a command, in any of the kiosk's languages.

The vocabulary for one question is the question's option labels and voice synonyms, numbers and
ordinals up to the number of options ("two", "number two", "the second", "la dos", "deux",
"option 2"), and the kiosk's commands (repeat, pause, continue, call the doctor, louder,
quieter); each language's words are in its file in ``kiosk/core/words``. Matching ignores case and
accents. Anything else -- an unsure recognition, a word that fits two options, noise the
recogniser turned into "[unk]" -- is *no match* with a reason: speech noise is never an answer.

:meth:`Matcher.phrases` lists every phrase the matcher understands, and is what
:mod:`kiosk.speech.grammar` turns into a recogniser grammar, so the recogniser can only ever
hear things the matcher knows.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Mapping, Sequence

from basis import record
from kiosk.core.channels import Command
from kiosk.core.words import LANGUAGES as KIOSK_LANGUAGES
from kiosk.core.words import Table, fill

#: the languages with speech words: every language with a words file
LANGUAGES = KIOSK_LANGUAGES

#: below this recogniser confidence an utterance is not an answer (see kiosk.speech.asr for the scale)
DEFAULT_MIN_CONFIDENCE = 0.6
#: a command needs this much: it acts at once, with no confirmation, and on voices other than
#: the kiosk's own short commands fit non-answers nearly as well as answers do ("uh" as
#: "stop", "all the time" as "call the doctor"; bench/asr.py)
COMMAND_MIN_CONFIDENCE = 0.8

# The words per language, from each language's words file (its ``speech`` section, in order).

#: cardinal words per language, 1..10; the first form of each is the one put in grammars first
CARDINALS: Mapping[str, tuple[tuple[str, ...], ...]] = Table(lambda words: words.speech["cardinals"])

#: ordinal words per language, 1st..10th
ORDINALS: Mapping[str, tuple[tuple[str, ...], ...]] = Table(lambda words: words.speech["ordinals"])

#: how a number is said around the number word: "{n}" is a cardinal, "{o}" an ordinal
NUMBER_FORMS: Mapping[str, tuple[str, ...]] = Table(lambda words: words.speech["number_forms"])

#: words that may surround a number without changing it ("it's number two please")
NUMBER_FILLERS: Mapping[str, frozenset[str]] = Table(lambda words: frozenset(words.speech["number_fillers"]))

#: words that may follow a number word without changing it ("the second one")
AFTER_NUMBER: Mapping[str, frozenset[str]] = Table(
    lambda words: frozenset(normalise(w) for w in words.speech["after_number"])
)

#: spoken commands per language (accents as spoken; matching ignores them)
COMMAND_PHRASES: Mapping[str, dict[Command, tuple[str, ...]]] = Table(
    lambda words: {Command(name): phrases for name, phrases in words.speech["commands"].items()}
)

#: commands that only mean something while the session is paused, and are left out of a
#: question's grammar: "go on" competed with "one" for nothing, as resuming is no answer
PAUSED_ONLY = frozenset({Command.RESUME})


def welcome_commands(language: str) -> dict[Command, tuple[str, ...]]:
    """What the welcome screen (and the explanation) listens for besides its options: only calling
    the doctor. Pausing, repeating or undoing mean nothing before a test starts, and their short
    words stole "start" there: by 6 of bench/asr.py's voices "start" was heard as "stop" 9 times
    in 18 (6 of them paused) and as "doctor" 5 times, "begin" as "again" or "repeat"."""
    return {Command.CALL_DOCTOR: COMMAND_PHRASES[language][Command.CALL_DOCTOR]}


def undo_commands(language: str) -> dict[Command, tuple[str, ...]]:
    """What the kiosk listens for in the thank-you gap after an answer: taking it back ("No,
    that's wrong", "change my answer") and calling the doctor."""
    return {command: COMMAND_PHRASES[language][command] for command in (Command.UNDO, Command.CALL_DOCTOR)}


#: natural ways to say yes / no, added to an option whose label is one of the first words (a
#: confirmation: "I heard: Independent. Is that right?"); a no option also takes the UNDO phrases
YES_NO: Mapping[str, tuple[tuple[str, ...], tuple[str, ...]]] = Table(
    lambda words: (words.speech["yes_words"], words.speech["no_words"])
)

#: the kiosk's languages by name, in any of its languages: a welcome option naming a language
#: ("Empezar en español") also takes these
LANGUAGE_NAMES: Mapping[str, tuple[str, ...]] = Table(lambda words: words.speech["names"])
#: ways to say "start": taken by a Start option, and in each language by the option naming it
START_WORDS: Mapping[str, tuple[str, ...]] = Table(lambda words: words.speech["start_words"])

#: words a patient may put before an answer ("I need a lot of help", "I think two"); the
#: recogniser's grammar allows one before any phrase, and matching ignores them
LEAD_INS: Mapping[str, tuple[str, ...]] = Table(lambda words: words.speech["lead_ins"])

#: what patients say that is not an answer: these are in the grammar so that "um", "what?" or
#: "I don't know" have somewhere to go other than the nearest answer; they match nothing
FILLERS: Mapping[str, tuple[str, ...]] = Table(lambda words: words.speech["fillers"])

#: words that turn a reply into a "no" wherever they are heard ("that's not what I said", "no I
#: said two"): a "yes" to "Is that right?" whose hearing holds one is never taken as said
NEGATIONS: Mapping[str, tuple[str, ...]] = Table(lambda words: words.speech["negations"])

#: ways of asking for help that answer a question rather than call anyone ("a bit of help", also
#: after a lead-in: "I need a bit of help"): where an option is chosen by saying "help" they
#: choose it (the word is in them); on a question without one they are in the grammar as no
#: answer, so they are never forced onto "I need a doctor" (issue 33). Not added to an option's
#: own phrases: more phrases there moved where answers end in talk (tests/kiosk/speech/test_rooms.py)
HELP_WORDS: Mapping[str, tuple[str, ...]] = Table(lambda words: words.speech["help_words"])

#: what recognisers emit for sounds outside their grammar
UNKNOWN_TOKENS = frozenset({"[unk]", "<unk>"})


def normalise(text: str) -> str:
    """Lower-case, accents removed, punctuation to spaces, single spaces ("¿Número dos?" → "numero dos")."""
    decomposed = unicodedata.normalize("NFKD", text.casefold())
    plain = "".join(c for c in decomposed if not unicodedata.combining(c))
    return " ".join(re.sub(r"[^\w\[\]]+", " ", plain).split())


def heard_negation(text: str, language: str) -> bool:
    """Whether ``text`` holds one of ``language``'s negations as whole words ("isn't" too)."""
    tokens = _tokens(text)
    return any(_find(_tokens(word), tokens) >= 0 for word in NEGATIONS[language])


def spoken_label(label: str) -> str:
    """The part of an option label a patient would say: without its parenthesised detail.

    "independent (bath or shower, unsupervised)" → "independent".
    """
    return " ".join(re.sub(r"\([^)]*\)", " ", label).split()).strip(" ,;:.")


@record
class OptionWords:
    """What may be said to choose one answer option, in one language."""

    label: str
    synonyms: tuple[str, ...] = ()


@record
class Match:
    """The outcome of matching one utterance: an option, a command, or neither and why."""

    option: int | None = None
    command: Command | None = None
    #: why there is no match (empty when there is one)
    reason: str = ""

    @property
    def matched(self) -> bool:
        """Whether the utterance was an answer or a command."""
        return self.option is not None or self.command is not None


def _tokens(phrase: str) -> tuple[str, ...]:
    return tuple(normalise(phrase).split())


def _find(needle: tuple[str, ...], haystack: tuple[str, ...]) -> int:
    """Start of ``needle`` as a run of whole words in ``haystack``, or -1."""
    n = len(needle)
    return next((i for i in range(len(haystack) - n + 1) if haystack[i : i + n] == needle), -1)


def _is_word(label: str, which: int, language: str) -> bool:
    """Whether ``label`` is a yes (``which`` 0) or no (1) word of ``language``."""
    return normalise(spoken_label(label)) in {normalise(w) for w in YES_NO[language][which][:2]}


def _with_known_words(option: OptionWords, language: str) -> OptionWords:
    """An option the kiosk itself offers, with the natural ways of saying it: Yes or No (a
    confirmation; No also takes the "that's wrong" phrases), Start, or a language's name (the
    welcome, where the option in the prompt's own language also takes "start")."""
    extra: tuple[str, ...] = ()
    label = normalise(spoken_label(option.label))
    for which in (0, 1):
        if _is_word(option.label, which, language):
            extra = YES_NO[language][which] + (COMMAND_PHRASES[language][Command.UNDO] if which else ())
    if label in {normalise(w) for w in START_WORDS[language][:2]}:
        extra = START_WORDS[language]
    words = set(label.split())
    for named, names in LANGUAGE_NAMES.items():
        if words & {normalise(n) for n in names if " " not in n}:
            extra += names + START_WORDS[named]
    if not extra:
        return option
    return OptionWords(option.label, tuple(dict.fromkeys((*option.synonyms, *extra))))


class Matcher:
    """Matches utterances against one question's options in one language.

    With no options (the session is paused, say) only the commands are understood.
    """

    def __init__(
        self,
        options: Sequence[OptionWords],
        language: str,
        min_confidence: float = DEFAULT_MIN_CONFIDENCE,
        paused: bool = False,
        commands: Mapping[Command, tuple[str, ...]] | None = None,
        numbers: bool = True,
    ) -> None:
        """``commands`` (command → phrases) replaces the language's whole set of spoken commands
        (:data:`COMMAND_PHRASES`), e.g. :func:`welcome_commands`; ``numbers=False`` leaves the
        options' numbers out of the grammar (the welcome: a language is said by its name)."""
        if language not in LANGUAGES:
            raise ValueError(f"no speech vocabulary for language {language!r} (have {', '.join(LANGUAGES)})")
        if len(options) > len(CARDINALS[language]):
            raise ValueError(f"at most {len(CARDINALS[language])} options can be spoken, got {len(options)}")
        self.options = tuple(_with_known_words(o, language) for o in options)
        self.language = language
        self.min_confidence = min_confidence
        no_option = next((n for n, o in enumerate(self.options, start=1) if _is_word(o.label, 1, language)), None)
        #: "Is that right?": Yes and No are said as words, never as numbers or after "I need" (the
        #: keys and the remote give 1 and 2 without the recogniser). With "number one" / "option
        #: one" in its grammar, "no, that's wrong" was heard as Yes on other voices in noise.
        self.yes_no = len(self.options) == 2 and _is_word(self.options[0].label, 0, language) and no_option == 2
        #: whether an option may be said by its number (not on the welcome: a fan's hum was heard
        #: as "four", a language, with 0.96 confidence once a fourth language came)
        self.numbers = numbers
        #: every command phrase in play (a yes/no question's UNDO phrases mean "no")
        self._command_phrases = dict(COMMAND_PHRASES[language] if commands is None else commands)
        #: a short list of commands (before the test, in the thank-you gap): no "I need ..." either
        #: ("begin" was heard as "i need two", Español, on the welcome)
        self._few_commands = commands is not None
        #: the commands listened for: RESUME only while paused; UNDO on a yes/no question means "no"
        self.commands = {
            c: p
            for c, p in self._command_phrases.items()
            if (paused or c not in PAUSED_ONLY) and not (c is Command.UNDO and no_option)
        }
        #: phrase tokens → what it selects; options first, so a clash is detected, not hidden
        self._targets: dict[tuple[str, ...], set[int | Command]] = {}
        for number, option in enumerate(self.options, start=1):
            for phrase in (spoken_label(option.label), *option.synonyms):
                if _tokens(phrase):
                    self._targets.setdefault(_tokens(phrase), set()).add(number)
        for command, phrases in self._command_phrases.items():
            for phrase in phrases:
                target = no_option if command is Command.UNDO and no_option else command
                if command in self.commands or target == no_option:
                    self._targets.setdefault(_tokens(phrase), set()).add(target)
        self._numbers: dict[str, int] = {}
        for table in (CARDINALS, ORDINALS):
            for number, words in enumerate(table[language][: len(self.options)], start=1):
                for word in words:
                    self._numbers[normalise(word)] = number
        self._numbers.update({str(n): n for n in range(1, len(self.options) + 1)})
        self._all_numbers = {
            normalise(word): number
            for table in (CARDINALS, ORDINALS)
            for number, words in enumerate(table[language], start=1)
            for word in words
        }

    def phrases(self) -> list[str]:
        """Every phrase this matcher understands, as written (accents kept), without repeats.

        Option labels and synonyms, every number form up to the number of options, and the
        commands; this is the recogniser's grammar for the question.
        """
        out: list[str] = []
        for option in self.options:
            out += [spoken_label(option.label), *option.synonyms]
        forms = NUMBER_FORMS[self.language] if not self.yes_no and self.numbers else ()
        for number in range(len(self.options)):
            for form in forms:
                words = CARDINALS[self.language][number] if "{n}" in form else ORDINALS[self.language][number]
                out += [fill(form, n=w, o=w) for w in words]
        for command, phrases in self._command_phrases.items():
            if command in self.commands or command is Command.UNDO:
                out += phrases
        seen: set[str] = set()
        unique = []
        for phrase in out:
            if phrase and normalise(phrase) not in seen:
                seen.add(normalise(phrase))
                unique.append(phrase)
        return unique

    def lead_ins(self) -> tuple[str, ...]:
        """Words the grammar allows before any phrase (:data:`LEAD_INS`)."""
        return () if self.yes_no or self._few_commands else LEAD_INS[self.language]

    def fillers(self) -> tuple[str, ...]:
        """Non-answers the grammar holds so they are not forced onto an answer (:data:`FILLERS`,
        and the ways of asking for help where no option is chosen by them, so that "I need a bit
        of help" is not forced onto "I need a doctor"), without any that would mean something
        here ("no" where no is an answer)."""
        helps = HELP_WORDS[self.language]
        # after the first lead-in ("i need some help"), the one that asks
        asked = [f"{lead} {words}" for lead in LEAD_INS[self.language][:1] for words in helps]
        others = (*FILLERS[self.language], *helps, *asked)
        return tuple(dict.fromkeys(f for f in others if not self.match(f).matched))

    def meaning(self, phrase: str) -> int | Command | str:
        """What saying ``phrase`` selects: an option number, a command, or else the phrase itself
        (the recogniser's ``set_grammar`` groups its phrases by this)."""
        match = self.match(phrase)
        return match.option if match.option is not None else (match.command or phrase)

    def _number(self, tokens: tuple[str, ...]) -> int | None:
        leads = sorted(map(_tokens, LEAD_INS[self.language]), key=len, reverse=True)
        lead = next((lead for lead in leads if tokens[: len(lead)] == lead), ())
        tokens = tokens[len(lead) :] if len(tokens) > len(lead) else tokens
        rest = [t for t in tokens if t not in NUMBER_FILLERS[self.language]]
        if len(rest) == 2 and rest[1] in AFTER_NUMBER[self.language] and rest[0] in self._numbers:
            rest = rest[:1]  # "the second one"
        if len(rest) == 1 and rest[0] in self._numbers:
            return self._numbers[rest[0]]
        if len(rest) == 1 and rest[0] in self._all_numbers:
            return -self._all_numbers[rest[0]]  # a number, but not one of this question's
        return None

    def match(self, utterance: str, confidence: float | None = None) -> Match:
        """Match one recognised utterance; ``confidence`` is the recogniser's, if it has one."""
        if confidence is not None and confidence < self.min_confidence:
            return Match(
                reason=f"unsure recognition of {utterance!r} (confidence {confidence:.2f} < {self.min_confidence:.2f})"
            )
        tokens = tuple(t for t in normalise(utterance).split() if t not in UNKNOWN_TOKENS)
        if not tokens:
            return Match(reason="nothing recognisable was said")
        number = self._number(tokens) if not self.yes_no and self.numbers else None
        if number is not None and number < 0:
            return Match(reason=f"there is no option {-number} on this question ({len(self.options)} options)")
        if number is not None:
            return Match(option=number)
        spans = []  # (start, end, targets) of every known phrase heard
        for phrase, targets in self._targets.items():
            start = _find(phrase, tokens)
            if start >= 0:
                spans.append((start, start + len(phrase), targets))
        # a phrase heard inside a longer one ("help" in "minor help") does not count on its own
        spans = [
            s
            for s in spans
            if not any(o is not s and o[0] <= s[0] and s[1] <= o[1] and o[1] - o[0] > s[1] - s[0] for o in spans)
        ]
        found: set[int | Command] = set().union(*(t for *_, t in spans)) if spans else set()
        if not found:
            return Match(reason=f"{utterance!r} is not an answer or a command here")
        if len(found) > 1:
            names = ", ".join(sorted(f"option {t}" if isinstance(t, int) else t.value for t in found))
            return Match(reason=f"{utterance!r} is ambiguous ({names})")
        (target,) = found
        if isinstance(target, Command):
            if confidence is not None and confidence < max(self.min_confidence, COMMAND_MIN_CONFIDENCE):
                return Match(
                    reason=f"unsure recognition of the command {utterance!r} "
                    f"(confidence {confidence:.2f} < {COMMAND_MIN_CONFIDENCE:.2f})"
                )
            return Match(command=target)
        return Match(option=target)
