"""PocketSphinx with the wheel's US-English model and a JSGF grammar per question.

A grammar decoder always returns *some* phrase, so the confidence is the lowest of three checks,
each simple enough to explain to a clinician:

1. a whole phrase was reached (else 0);
2. coverage: the recognised words cover the utterance's voiced audio (a sentence forced onto the
   grammar goes mostly into "silence"); where people talk nearby only audio standing out of the
   room heard in the pre-roll counts (:func:`~kiosk.speech.asr.levels.above_room`);
3. fit: the grammar's best path costs, per voiced frame, about what free phone decoding of the
   same audio costs; :data:`PS_FIT_MIDPOINT` and :data:`PS_FIT_SPREAD` map the difference to
   [0, 1]. The difference, not an absolute cost, because it is one yardstick for every voice
   and room. The utterance is scored with a fixed quiet tail, so an early close scores like a late one.

Before scoring, a steady noise is subtracted (:mod:`kiosk.speech.denoise`), or else the talk of
people nearby is turned down around the patient's words (:func:`~kiosk.speech.asr.levels.gate_talk`);
a reply acted on without asking back is refused where the utterance as heard is surely another option.
A phrase holding a confusable word (:data:`PS_CONFUSABLE_WORDS`) is flagged
(``Recognition.confusable``) so the voice channel always asks it back; a lone such word scores 0.
The dictionary is widened for accents (:func:`accent_variants`, :data:`PS_ACCENT_WORDS`).

Why each rule and constant has its value, and the designs tried and not kept:
docs/speech-tuning.md; measured: bench/RESULTS.md.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Hashable, Sequence
from pathlib import Path

import numpy as np

from kiosk.speech.asr.base import AsrUnavailable, NoModelForLanguage, Recognition
from kiosk.speech.asr.levels import PS_TRAILING_FRAMES, above_room, fixed_tail, gate_talk, voiced_frames
from kiosk.speech.denoise import reduce_steady_noise
from kiosk.speech.grammar import Grammar, build_grammar, confusable_phrases, final_phrases, to_jsgf

log = logging.getLogger(__name__)

#: the fit (phrase cost minus free-phone cost per voiced frame) where the acoustic confidence
#: is 0.5, and how fast it falls around it; set on bench/asr.py's dev voices
PS_FIT_MIDPOINT, PS_FIT_SPREAD = 2.2, 0.35
#: the free phone-loop search's name in the decoder
_PHONES = "phones"
#: after steady noise was subtracted (:mod:`kiosk.speech.denoise`), a frame is speech only this
#: far above the utterance's quietest tenth: the residue of a fan is no speech, and counting it
#: made the words seem to go on to the end of the hangover
PS_VOICED_ABOVE_CLEANED_DB = 10.0
#: a reply acted on without asking back (a confirmation's yes or no) and heard with the talk
#: turned down is refused where the utterance as it came in is heard as another option at
#: least this sure (the matcher's own minimum for an answer, DEFAULT_MIN_CONFIDENCE)
PS_OTHER_HEARING_MIN = 0.6
#: words the wheel's English model cannot tell apart on espeak-ng speech: "the first one" was
#: heard as "the third one", and no score margin separates them
PS_CONFUSABLE_WORDS: tuple[frozenset[str], ...] = (frozenset({"first", "third"}),)

#: words of the welcome the wheel's English dictionary lacks, as a patient would say them
#: (CMU phones): the language names and "start" in Spanish and French
PS_EXTRA_WORDS = {
    "español": "EH S P AA N Y OW L",
    "espanol": "EH S P AA N Y OW L",
    "français": "F R AA N S EY",
    "francais": "F R AA N S EY",
    "français(2)": "F R AA N S EH",
    "français(3)": "F R AO S EH",
    "français(4)": "F AA S EH",
    "empezar": "EH M P EY S AA R",
    "commencer": "K AO M AA N S EY",
}

#: how British and other accents say words the wheel's US dictionary spells one way only, added
#: as alternative pronunciations: "one" with the vowel of "lot" (espeak-ng's en-gb voices, the
#: North of England), which the dictionary's only "W AH N" lost to the filler "what" (W AA T)
PS_ACCENT_WORDS = {"one": ("W AA N",)}
#: the dictionary's vowels (CMU phones), for the non-rhotic rule in :func:`accent_variants`
_VOWELS = frozenset("AA AE AH AO AW AY EH ER EY IH IY OW OY UH UW".split())

#: lattice entries that are not words the patient said
_FILLERS = {"<s>", "</s>", "<sil>", "(NULL)", "[NOISE]", "[SPEECH]"}


class PocketSphinxRecogniser:
    """PocketSphinx with the wheel's US-English model and a JSGF grammar per question."""

    name = "pocketsphinx"
    #: why a better recogniser is not used ("" when none would be)
    fallback = ""

    def __init__(self, language: str = "en") -> None:
        if language != "en":
            raise NoModelForLanguage(
                f"no speech model for language {language!r}: pocketsphinx only "
                f"ships English; install one with `kiosk models install {language}`"
            )
        try:
            from pocketsphinx import Decoder
        except ImportError as exc:
            raise AsrUnavailable(f"pocketsphinx is not installed ({exc})") from None
        self.language = language
        # no bestpath lattice rescoring: it picked prefixes like "the" over whole phrases
        self._decoder = Decoder(lm=None, bestpath=False, loglevel="FATAL")
        from pocketsphinx import get_model_path

        # free phone decoding of the same audio: the yardstick the answer's fit is measured by
        self._decoder.add_allphone_file(_PHONES, str(Path(get_model_path()) / "en-us" / "en-us-phone.lm.bin"))
        for word, phones in PS_EXTRA_WORDS.items():
            if self._decoder.lookup_word(word) is None:
                self._decoder.add_word(word, phones, False)
        #: words whose accent variants (:func:`accent_variants`) have been added
        self._accented: set[str] = set()
        self._in_utterance = False
        self._grammar: Grammar | None = None
        self._grammars = 0
        #: phrases holding a word confusable with one in a phrase of another meaning
        self._confusable: frozenset[str] = frozenset()
        #: phrases that are a whole answer once heard (partial results say so)
        self._final: frozenset[str] = frozenset()
        #: what each phrase of the grammar selects (see :meth:`set_grammar`)
        self._meaning: Callable[[str], Hashable] = lambda p: p
        #: options heard are acted on without being asked back (see :meth:`set_grammar`)
        self._taken_as_heard = False
        #: whether a whole utterance has been decoded (see :meth:`accept`)
        self._settled = False
        self._pcm = bytearray()

    def set_grammar(
        self,
        phrases: Sequence[str],
        meaning: Callable[[str], Hashable] | None = None,
        lead_ins: Sequence[str] = (),
        fillers: Sequence[str] = (),
        taken_as_heard: bool = False,
    ) -> Grammar:
        """Compile the phrases the dictionary knows to JSGF and make it the active search.

        ``meaning`` groups phrases that select the same thing: "the first one" is only
        confusable where "the third one" selects something else. With ``taken_as_heard``, an
        option heard with the talk around it turned down (:func:`~kiosk.speech.asr.levels.gate_talk`) must not be
        another option when heard as it came in (see :meth:`finish`).
        """
        self._taken_as_heard = taken_as_heard
        grammar = build_grammar(
            phrases, lambda w: self._decoder.lookup_word(w) is not None, self.name, lead_ins, fillers, meaning
        )
        for phrase in (*grammar.phrases, *grammar.lead_ins, *grammar.fillers):
            for word in phrase.split():
                self._add_accents(word)
        self._end()
        # a fresh search name each time: pocketsphinx keeps searches by name
        self._grammars += 1
        name = f"q{self._grammars}"
        self._decoder.add_jsgf_string(name, to_jsgf(grammar))
        self._decoder.activate_search(name)
        if self._grammars > 1:
            self._decoder.remove_search(f"q{self._grammars - 1}")
        self._grammar = grammar
        meaning = meaning or (lambda p: p)
        self._meaning = meaning
        self._confusable = confusable_phrases(grammar.phrases, meaning, PS_CONFUSABLE_WORDS)
        self._final = final_phrases(grammar.phrases, meaning)
        return grammar

    def _add_accents(self, word: str) -> None:
        """Add the word's accent variants to the dictionary as alternatives ("number(2)")."""
        if word in self._accented:
            return
        self._accented.add(word)
        known: list[str] = []
        while phones := self._decoder.lookup_word(word if not known else f"{word}({len(known) + 1})"):
            known.append(phones)
        wanted = [*PS_ACCENT_WORDS.get(word, ()), *(v for p in known for v in accent_variants(p))]
        for phones in dict.fromkeys(wanted):
            if phones not in known:
                known.append(phones)
                self._decoder.add_word(f"{word}({len(known)})", phones, False)

    def _end(self) -> None:
        if self._in_utterance:
            self._decoder.end_utt()
            self._in_utterance = False
        self._pcm.clear()

    def reset(self) -> None:
        """Drop any utterance in progress."""
        self._end()

    def close(self) -> None:
        """End the utterance without scoring it (another recogniser decodes it, see
        :mod:`kiosk.speech.asr.whisper`): the cepstral mean has heard the voice, so later partial
        results may end a turn early."""
        self._end()
        self._settled = True

    def accept(self, pcm: bytes) -> Recognition | None:
        """Decode more audio; returns the best partial hypothesis so far (if any)."""
        if self._grammar is None:
            raise RuntimeError("set_grammar must be called before recognising")
        if not self._in_utterance:
            self._decoder.start_utt()
            self._in_utterance = True
        self._pcm += pcm
        self._decoder.process_raw(pcm, False, False)
        hyp = self._decoder.hyp()
        if hyp is None or not hyp.hypstr:
            return None
        # A fresh decoder's cepstral mean has not settled on the voice and room yet: its first
        # utterance closed early scored far better than it should ("banana split" taken for
        # "number three"), so the first utterance always gets the long hangover.
        complete = self._settled and self._grammar.core(hyp.hypstr) in self._final
        return Recognition(hyp.hypstr, 0.0, final=False, complete=complete)

    def finish(self) -> Recognition:
        """End the utterance and score it (see the module docstring)."""
        if not self._in_utterance:
            return Recognition("", 0.0)
        # a fan's or a corridor's steady noise is taken out first: it is scored as speech
        # otherwise (see kiosk.speech.denoise)
        heard = bytes(self._pcm)
        pcm = reduce_steady_noise(heard)
        cleaned = pcm is not heard
        # people talking around a short answer: only the patient's words are scored
        gated = pcm if cleaned else gate_talk(pcm)
        self._end()
        self._settled = True
        result, core = self._score(gated, cleaned)
        assert self._grammar is not None  # an utterance is only scored under a grammar
        answers = self._grammar.answers
        if self._taken_as_heard and gated is not pcm and result.confidence > 0 and core in answers:
            # acted on without asking back: heard with the talk turned down and as it came in,
            # one reply must not be two different options, each taken (see levels.gate_talk)
            other, other_core = self._score(pcm, cleaned)
            if (
                other.confidence >= PS_OTHER_HEARING_MIN
                and other_core in answers
                and self._meaning(other_core) != self._meaning(core)
            ):
                log.debug("pocketsphinx: %r, but %r with the talk left in", result.text, other.text)
                return Recognition(result.text, 0.0)
        return result

    def _score(self, pcm: bytes, cleaned: bool) -> tuple[Recognition, str]:
        """Decode one view of the utterance and score it; also the phrase heard, without its
        lead-in. ``cleaned``: a steady noise was subtracted from it."""
        # what is left of a subtracted noise lies within 30 dB of the words but is no speech:
        # where the words end, and what they must cover, leave it out
        voiced = voiced_frames(pcm, PS_VOICED_ABOVE_CLEANED_DB if cleaned else None)
        if voiced.any():
            pcm, voiced = fixed_tail(pcm, voiced)
        # the costs per frame stay counted over every frame within 30 dB of the loudest (the
        # tail excepted), the yardstick PS_FIT_MIDPOINT was set on
        counted = voiced
        if cleaned and voiced.any():
            counted = voiced_frames(pcm)[: len(voiced)]
            counted[len(voiced) - PS_TRAILING_FRAMES :] = False
            if not counted.any():
                counted = voiced
        # Decode the utterance once more: live cepstral mean normalisation only settles on a
        # voice after hearing it, and a fresh decoder's first utterance was misheard ("pause"
        # as "cannot"). The second pass starts from the means of this very utterance.
        self._decoder.start_utt()
        self._decoder.process_raw(pcm, False, True)
        self._decoder.end_utt()
        hyp = self._decoder.hyp()
        if hyp is None or not hyp.hypstr:
            return Recognition("", 0.0), ""
        words = [seg for seg in self._decoder.seg() if seg.word not in _FILLERS]
        assert self._grammar is not None  # an utterance is only scored under a grammar
        core = self._grammar.core(hyp.hypstr)
        if not words or core not in self._grammar.phrases or not voiced.any():
            return Recognition(hyp.hypstr, 0.0), core  # stopped inside a phrase: not something said
        in_words = np.zeros(len(voiced), dtype=bool)
        for seg in words:
            in_words[seg.start_frame : seg.end_frame + 1] = True
        # in a room that talks, coverage counts only what stands out of the room (see levels.above_room)
        speech = voiced if cleaned else voiced & above_room(pcm, len(voiced))
        speech = speech if speech.any() else voiced
        coverage = float((speech & in_words).sum() / speech.sum())
        free = self._free_cost(pcm, counted)
        fit = _cost(hyp.score, counted) - free if math.isfinite(free) else math.inf
        acoustic = _sigmoid((PS_FIT_MIDPOINT - fit) / PS_FIT_SPREAD)
        # a phrase the model cannot tell from another answer's is only taken once confirmed; a
        # lone such word not at all: a fan switched on mid-answer was heard as "first" (0.998)
        confusable = core in self._confusable
        if confusable and len(core.split()) == 1:
            acoustic = 0.0
        log.debug(
            "pocketsphinx: %r coverage %.2f fit %.2f (confidence %.2f) confusable %s",
            hyp.hypstr,
            coverage,
            fit,
            acoustic,
            confusable,
        )
        return Recognition(hyp.hypstr, min(coverage, acoustic), fit=fit, confusable=confusable), core

    def _free_cost(self, pcm: bytes, voiced: np.ndarray) -> float:
        """The cost per voiced frame of the best free phone sequence for the same audio."""
        grammar = self._decoder.current_search()
        self._decoder.activate_search(_PHONES)
        try:
            self._decoder.start_utt()
            self._decoder.process_raw(pcm, False, True)
            self._decoder.end_utt()
            hyp = self._decoder.hyp()
        finally:
            self._decoder.activate_search(grammar)
        return _cost(hyp.score, voiced) if hyp is not None else math.inf


def accent_variants(phones: str) -> list[str]:
    """Other ways accents say a pronunciation (CMU phones): the non-rhotic one (British English,
    much of the world), where an "r" not followed by a vowel is not spoken and a word's final
    "-er" is a schwa: "number" N AH M B ER → N AH M B AH, "four" F AO R → F AO."""
    out = phones.split()
    for i in range(len(out) - 1, -1, -1):
        follows_vowel = i + 1 < len(out) and out[i + 1] in _VOWELS
        if out[i] == "R" and i > 0 and out[i - 1] in _VOWELS and out[i - 1] != "ER" and not follows_vowel:
            del out[i]
        elif out[i] == "ER" and i == len(out) - 1:
            out[i] = "AH"
    variant = " ".join(out)
    return [variant] if variant != phones and out else []


def _cost(score: float, voiced: np.ndarray) -> float:
    """A path score (pocketsphinx's logmath.exp of log base 1.0001) as cost per voiced frame."""
    return -math.log(score) * 1000 / voiced.sum() if score > 0 else math.inf


def _sigmoid(x: float) -> float:
    """Logistic function, clamped so that exp never overflows."""
    return 1 / (1 + math.exp(-max(-50.0, min(50.0, x))))
