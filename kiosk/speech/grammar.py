"""Per-question recogniser grammars, built from the matcher's phrases.

The recogniser is constrained to what the current question can mean (its options' labels and
synonyms, number words, commands, see :meth:`kiosk.speech.matching.Matcher.phrases`), which is
what makes short answers from older voices recognisable at all. Every word must be known to the
recogniser's dictionary; a phrase with an unknown word is left out and the reason logged, since
the recogniser could never hear it anyway.
"""

from __future__ import annotations

import json
import logging
import re
from collections.abc import Callable, Hashable, Sequence

from basis import record

log = logging.getLogger(__name__)


def recogniser_words(phrase: str) -> list[str]:
    """A phrase as recognisers write it: lower case, accents and apostrophes kept, no punctuation."""
    return re.sub(r"[^\w' -]+", " ", phrase.lower()).replace("-", " ").split()


@record
class Grammar:
    """The phrases a recogniser will listen for, and those left out (phrase, why).

    ``lead_ins`` may come before an answer phrase ("i need" a lot of help), not before a command;
    ``fillers`` are non-answers ("um", "what") that give other speech somewhere to go but the
    nearest answer.
    """

    phrases: tuple[str, ...]
    dropped: tuple[tuple[str, str], ...] = ()
    lead_ins: tuple[str, ...] = ()
    fillers: tuple[str, ...] = ()
    #: the phrases that select an answer option (a lead-in may come before these)
    answers: tuple[str, ...] = ()

    def core(self, text: str) -> str:
        """``text`` without a lead-in, when what follows is an answer phrase; else ``text``."""
        for lead in sorted(self.lead_ins, key=len, reverse=True):
            if text.startswith(lead + " ") and text[len(lead) + 1 :] in self.answers:
                return text[len(lead) + 1 :]
        return text


def build_grammar(
    phrases: Sequence[str],
    known: Callable[[str], bool],
    recogniser: str,
    lead_ins: Sequence[str] = (),
    fillers: Sequence[str] = (),
    meaning: Callable[[str], Hashable] | None = None,
) -> Grammar:
    """Keep the phrases whose every word ``known`` accepts; log and list the others. Lead-ins
    and fillers with an unknown word, or that are also phrases, are left out silently; lead-ins
    go only before the phrases whose ``meaning`` is an option number."""
    dropped: list[tuple[str, str]] = []
    kept = _known(phrases, known, recogniser, dropped)
    extra = [p for p in _known(lead_ins, known, "", []) if p not in kept]
    noise = [p for p in _known(fillers, known, "", []) if p not in kept]
    answers = [p for p in kept if meaning is not None and isinstance(meaning(p), int)]
    return Grammar(tuple(kept), tuple(dropped), tuple(extra) if answers else (), tuple(noise), tuple(answers))


def _known(
    phrases: Sequence[str], known: Callable[[str], bool], recogniser: str, dropped: list[tuple[str, str]]
) -> list[str]:
    kept: list[str] = []
    for phrase in phrases:
        words = recogniser_words(phrase)
        unknown = [w for w in words if not known(w)]
        if not words:
            continue
        if unknown:
            if recogniser:
                reason = f"{', '.join(repr(w) for w in unknown)} not in the {recogniser} dictionary"
                log.info("grammar: leaving out %r: %s", phrase, reason)
                dropped.append((phrase, reason))
            continue
        text = " ".join(words)
        if text not in kept:
            kept.append(text)
    return kept


def confusable_phrases(
    phrases: Sequence[str], meaning: Callable[[str], Hashable], confusable: Sequence[frozenset[str]]
) -> frozenset[str]:
    """The phrases a recogniser cannot be trusted on: they hold a word of one of the
    ``confusable`` sets, and a phrase of another meaning holds another word of that set.

    "the first one" is confusable where "the third one" selects another option, not where the
    question has only two options or both words select the same thing.
    """
    words = {p: set(p.split()) for p in phrases}
    out = set()
    for phrase in phrases:
        for group in confusable:
            mine = words[phrase] & group
            if mine and any(meaning(other) != meaning(phrase) and words[other] & (group - mine) for other in phrases):
                out.add(phrase)
    return frozenset(out)


def final_phrases(phrases: Sequence[str], meaning: Callable[[str], Hashable]) -> frozenset[str]:
    """The phrases that are a whole answer as soon as they are heard: no longer phrase of
    another meaning goes on from them.

    "needs" is no phrase at all; "help" is final unless, say, "help me up" selected another
    option; "the second" is final although "the second one" goes on from it, since both select
    option 2. Hearing a final phrase lets the endpointer stop waiting early.
    """
    words = {p: p.split() for p in phrases}
    return frozenset(
        p
        for p in phrases
        if not any(
            len(words[o]) > len(words[p]) and words[o][: len(words[p])] == words[p] and meaning(o) != meaning(p)
            for o in phrases
        )
    )


#: the prior of the filler branch in a JSGF grammar, against the answers' (see to_jsgf)
FILLER_WEIGHT = 0.05


def to_jsgf(grammar: Grammar, name: str = "answer") -> str:
    """A JSGF grammar (pocketsphinx) accepting exactly one of the phrases."""
    if not grammar.phrases:
        raise ValueError("a grammar needs at least one phrase the recogniser knows")
    lines = ["#JSGF V1.0;", f"grammar {name};"]
    top = "<phrase>"
    others = [p for p in grammar.phrases if p not in grammar.answers]
    if grammar.lead_ins:
        top = "[<lead>] <option>" + (" | <other>" if others else "")
        lines.append(f"<lead> = {' | '.join(grammar.lead_ins)} ;")
        lines.append(f"<option> = {' | '.join(grammar.answers)} ;")
        if others:
            lines.append(f"<other> = {' | '.join(others)} ;")
    if grammar.fillers:
        # a filler is the likelier reading only where it fits clearly better than any phrase
        top = f"/{1 - FILLER_WEIGHT}/ ({top}) | /{FILLER_WEIGHT}/ <filler>"
        lines.append(f"<filler> = {' | '.join(grammar.fillers)} ;")
    if not grammar.lead_ins:
        lines.append(f"<phrase> = {' | '.join(grammar.phrases)} ;")
    lines.append(f"public <{name}> = {top} ;")
    return "\n".join(lines) + "\n"


def to_vosk(grammar: Grammar) -> str:
    """A Vosk grammar: a JSON list of phrases plus "[unk]", so other speech has somewhere to go."""
    with_leads = [f"{lead} {p}" for lead in grammar.lead_ins for p in grammar.answers]
    return json.dumps([*grammar.phrases, *with_leads, *grammar.fillers, "[unk]"], ensure_ascii=False)
