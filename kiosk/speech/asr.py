"""Speech recognisers behind one small interface: Vosk (primary) and PocketSphinx (fallback).

A :class:`Recogniser` takes one utterance at a time (16 kHz mono int16 PCM, see
:mod:`kiosk.speech.audio`) under a per-question grammar and returns its text with a confidence
in [0, 1]:

- :class:`VoskRecogniser`: a Kaldi model installed with `kiosk models install LANG` (or given by
  ``KIOSK_VOSK_MODEL``), grammar as a JSON phrase list with "[unk]"; confidence is the lowest
  word confidence Vosk reports.
- :class:`PocketSphinxRecogniser`: the English model in the pocketsphinx wheel, grammar as JSGF.
  The finished utterance is first cleaned of steady noise (a fan; :mod:`kiosk.speech.denoise`);
  where people talk nearby, their talk around the patient's words is turned down instead
  (:func:`_gate_talk`), and a reply acted on without being asked back (a confirmation's yes)
  is refused where the utterance as heard, talk and all, is surely another option.
  A grammar decoder always returns *some* phrase, so its confidence is the lowest of these
  checks, each simple enough to explain to a clinician:

  1. a whole phrase was reached (else 0);
  2. coverage: the recognised words cover the utterance's voiced audio (a sentence forced
     onto the grammar goes mostly into "silence": 5-45 % covered, an answer 80-100 %). Where
     people talk nearby, only audio standing out of the room heard in the pre-roll counts
     (:func:`_above_room`): their talk around a short "two" or "no" is not the patient's;
  3. fit: the phrase fits the audio nearly as well as free phone decoding does. The cost per
     voiced frame of the grammar's best path is compared with that of the best free phone
     sequence for the same audio (the wheel's phone language model): an answer costs about as
     much as free phones, a sentence forced onto the grammar much more. An absolute cost (the
     first design) was tuned on the kiosk's own voice: right answers by other espeak-ng voices
     cost 6-9.7 per frame against 3.9-6.5 for the kiosk's, so "yes" in a female voice scored 0;
     the difference to free phones is the same yardstick for every voice and room.
     :data:`PS_FIT_MIDPOINT` and :data:`PS_FIT_SPREAD` (set on bench/asr.py's dev voices) map
     it to [0, 1]. The utterance is scored with a fixed quiet tail (:func:`_fixed_tail`), so
     one the endpointer closed early is scored like one closed late;
  Besides the confidence, a phrase holding a confusable word (:data:`PS_CONFUSABLE_WORDS`) is
  flagged (``Recognition.confusable``) wherever its partner selects another answer
  (:func:`kiosk.speech.grammar.confusable_phrases`). The kiosk's own voice's "the first one"
  was heard as "the third one" on every question with a third option, and decoded against
  each phrase alone "the third one" even fits it better, so no score margin separates them.
  Such a phrase is never taken on its own: the voice channel always asks "I heard: X. Is that
  right?" for it, and refuses it where nothing can be asked back. It used to score 0 (asked
  again), which cost 12 of 115 answers on bench/asr.py's dev voices in a quiet room although
  they heard it right 11 times in 13. A lone confusable word ("first") still scores 0: white
  noise switched on mid-answer was heard as "first" with confidence 0.998.

  Not used: a margin over the best phrase of another meaning (the utterance decoded again
  under a grammar without the recognised phrase's meaning). Measured here it rejected right
  answers and commands ("call the doctor", a first "independent") because the smaller
  grammar's search found rivals such as "go on" that the full search had pruned, even from
  the same cepstral mean; on the benchmark it traded 9 right answers for 2 wrong ones. Tried
  again for a confirmation's "yes" (one "no it isn't" in reverb was heard as "yes it is",
  confidence 0.998, margin -0.24): the smaller grammar gives each phrase a larger share, so
  the margin leans against the phrase heard, and two held-out voices' "that's right" never
  got past it (held-out right answers in a quiet room 0.79 -> 0.74).

  The dictionary's one pronunciation per word is widened for accents (:func:`accent_variants`,
  :data:`PS_ACCENT_WORDS`): a British "number" ends in a schwa, and the model's silence fitted
  it better than N AH M B ER, so "number two" was heard as "two" with half its audio uncovered.

:func:`open_recogniser` picks Vosk when a model for the language is installed, else
PocketSphinx for English, else raises :class:`AsrUnavailable` with the reason voice in is off.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from kiosk.speech.audio import SAMPLE_RATE, frame_powers
from kiosk.speech.denoise import reduce_steady_noise
from kiosk.speech.grammar import Grammar, build_grammar, confusable_phrases, final_phrases, to_jsgf, to_vosk

log = logging.getLogger(__name__)


class AsrUnavailable(RuntimeError):
    """Voice in cannot work for this language here; the message is one sentence for the UI."""


class NoModelForLanguage(AsrUnavailable):
    """No speech model for the language (Spanish or French without a Vosk model): the one
    reason a patient can be told, in their language (screen text ``voice_no_model``)."""

    reason_key = "voice_no_model"


@dataclass(frozen=True)
class Recognition:
    """What a recogniser made of (part of) an utterance."""

    text: str
    #: in [0, 1]; 0 when nothing was recognised
    confidence: float
    #: False for a partial result while the patient is still speaking
    final: bool = True
    #: for a partial result: it already is a whole answer (one of the grammar's
    #: :func:`~kiosk.speech.grammar.final_phrases`), so the endpointer need not wait long
    complete: bool = False
    #: pocketsphinx: how much worse the phrase fits the audio than free phones do (cost per
    #: voiced frame); the acoustic part of the confidence, kept for bench/asr.py's calibration
    fit: float | None = None
    #: the phrase holds a word the model cannot tell from one of another answer ("first" /
    #: "third"): never taken without asking the patient back (see :class:`PocketSphinxRecogniser`)
    confusable: bool = False


class Recogniser(Protocol):
    """One recogniser, one utterance at a time, under the current question's grammar."""

    #: "vosk" or "pocketsphinx", shown as the voice channel's source
    name: str
    language: str

    def set_grammar(
        self,
        phrases: Sequence[str],
        meaning: Callable[[str], Hashable] | None = None,
        lead_ins: Sequence[str] = (),
        fillers: Sequence[str] = (),
        taken_as_heard: bool = False,
    ) -> Grammar:
        """Listen only for these phrases (each maybe after one lead-in, or one of the fillers)
        from the next utterance on; returns what was kept.

        ``meaning(phrase)`` says what a phrase selects (an option number, a command): phrases
        with the same meaning are not rivals of one another (see :class:`PocketSphinxRecogniser`).
        Without it every phrase means only itself. ``taken_as_heard``: an option heard under
        this grammar is acted on without being asked back (a confirmation's yes or no), so a
        recogniser that can hear it two ways should make sure both agree.
        """

    def reset(self) -> None:
        """Forget the current utterance and get ready for a new one."""

    def accept(self, pcm: bytes) -> Recognition | None:
        """Take more audio of the current utterance; may return a partial result."""

    def finish(self) -> Recognition:
        """End the current utterance and return the final result."""


# --- PocketSphinx ----------------------------------------------------------------------------

#: the fit (phrase cost minus free-phone cost per voiced frame) where the acoustic confidence
#: is 0.5, and how fast it falls around it (see the docstring)
PS_FIT_MIDPOINT, PS_FIT_SPREAD = 2.2, 0.35
#: the free phone-loop search's name in the decoder
_PHONES = "phones"
#: 10 ms frames of quiet after the last voiced one that the final decode scores: the long
#: hangover's worth (see :func:`_fixed_tail`)
PS_TRAILING_FRAMES = 50
#: after steady noise was subtracted (:mod:`kiosk.speech.denoise`), a frame is speech only this
#: far above the utterance's quietest tenth: the residue of a fan lies within 30 dB of the
#: words, so the words seemed to go on to the end of the hangover and the scored utterance kept
#: all of it. Cut where the words end, right answers in white noise on bench/asr.py's dev
#: voices (10 cases each) went from 26 to 34 of 52 at SNR 10 dB, 42 to 45 of 51 at 20 dB
PS_VOICED_ABOVE_CLEANED_DB = 10.0
#: the utterance's first 10 ms frames, the endpointer's pre-roll, are the room it was said in
#: (:func:`_above_room`) ...
PS_ROOM_FRAMES = 20
#: ... and where people talk nearby, coverage counts only the frames this far above the loudest
#: tenth of it. Counting their talk around a short answer held "two" or "no" to 0.35 coverage:
#: bench/asr.py's background talk at SNR 10 dB, 10 cases per voice, right answers: dev voices
#: 18 -> 23 of 48, held-out 23 -> 25 of 45, 0 wrong stored
PS_ABOVE_ROOM_DB = 2.0
#: only a start at least this far below the loudest frame is taken for room
PS_ROOM_BELOW_SPEECH_DB = 6.0
#: a room whose sound even at the quietest tenth of an utterance (the pre-roll and the hangover
#: hold at least half a second of it) is this loud is one where people talk nearby: the level
#: the endpointer takes for speech at all (:attr:`kiosk.speech.audio.EndpointerSettings.min_speech_db`).
#: A microphone's hiss (-75 dBFS) and a quiet ward are far below it, also where an answer was
#: cut in two and the second part's pre-roll holds the first (the pre-roll alone took 1 of 21
#: answers in the -20 dB and telephone rooms); a fan's noise is subtracted instead (:mod:`denoise`)
PS_TALKING_ROOM_DB = -55.0
#: in such a room the talk around the patient's words is turned down by this much before the
#: utterance is scored (:func:`_gate_talk`) ...
PS_TALK_GATE_DB = -30.0
#: ... keeping this many 10 ms frames on either side of the patient's words, for the quiet
#: edges of a word ("yes" ends in a soft "s")
PS_TALK_GATE_KEEP_FRAMES = 10
#: a reply acted on without asking back (a confirmation's yes or no) and heard with the talk
#: turned down is refused where the utterance as it came in is heard as another option at
#: least this sure (the matcher's own minimum for an answer, DEFAULT_MIN_CONFIDENCE). Refusing
#: it whenever the other hearing's best phrase was another option, however unsure (a grammar
#: decoder always has one), took bench/asr.py's held-out right answers in background talk from
#: 0.60 to 0.55; checking every answer so, not only those acted on at once, to 0.54
PS_OTHER_HEARING_MIN = 0.6
#: words the wheel's English model cannot tell apart on espeak-ng speech (see the docstring)
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

#: bytes per 10 ms frame, pocketsphinx's frame rate
_FRAME_BYTES = 2 * SAMPLE_RATE // 100

#: lattice entries that are not words the patient said
_FILLERS = {"<s>", "</s>", "<sil>", "(NULL)", "[NOISE]", "[SPEECH]"}


class PocketSphinxRecogniser:
    """PocketSphinx with the wheel's US-English model and a JSGF grammar per question."""

    name = "pocketsphinx"

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
        # bestpath lattice rescoring picked prefixes like "the" over whole phrases: on the
        # synthesised answer set 76 of 109 right with it, 96 without
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
        option heard with the talk around it turned down (:func:`_gate_talk`) must not be
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
        # utterance closed early scored far better than it should ("banana split" as "number
        # three": cost 6.4 against 6.7 after the long hangover, 7.1 once settled), so the
        # first utterance always gets the long hangover.
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
        gated = pcm if cleaned else _gate_talk(pcm)
        self._end()
        self._settled = True
        result, core = self._score(gated, cleaned)
        answers = self._grammar.answers
        if self._taken_as_heard and gated is not pcm and result.confidence > 0 and core in answers:
            # acted on without asking back: heard with the talk turned down and as it came in,
            # one reply must not be two different options, each taken (see _gate_talk)
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
        voiced = _voiced_frames(pcm, PS_VOICED_ABOVE_CLEANED_DB if cleaned else None)
        if voiced.any():
            pcm, voiced = _fixed_tail(pcm, voiced)
        # the costs per frame stay counted over every frame within 30 dB of the loudest (the
        # tail excepted), the yardstick PS_FIT_MIDPOINT was set on
        counted = voiced
        if cleaned and voiced.any():
            counted = _voiced_frames(pcm)[: len(voiced)]
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
        core = self._grammar.core(hyp.hypstr)
        if not words or core not in self._grammar.phrases or not voiced.any():
            return Recognition(hyp.hypstr, 0.0), core  # stopped inside a phrase: not something said
        in_words = np.zeros(len(voiced), dtype=bool)
        for seg in words:
            in_words[seg.start_frame : seg.end_frame + 1] = True
        # in a room that talks, coverage counts only what stands out of the room (see _above_room)
        speech = voiced if cleaned else voiced & _above_room(pcm, len(voiced))
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


def _fixed_tail(pcm: bytes, voiced: np.ndarray) -> tuple[bytes, np.ndarray]:
    """The utterance with exactly :data:`PS_TRAILING_FRAMES` of quiet after its last voiced frame.

    The cost per voiced frame also counts the quiet after the speech, so an utterance the
    endpointer closed early (a whole answer after a short pause) would score better than the
    same one closed after the long hangover. Cutting a longer tail, and lengthening a shorter
    one by repeating the quiet actually heard (the room's own noise), scores both alike.
    """
    step = _FRAME_BYTES
    end = (int(np.flatnonzero(voiced)[-1]) + 1) * step
    tail = pcm[end : end + PS_TRAILING_FRAMES * step] or b"\0" * step
    tail = (tail * (PS_TRAILING_FRAMES * step // len(tail) + 1))[: PS_TRAILING_FRAMES * step]
    out = pcm[:end] + tail
    return out, np.concatenate([voiced[: end // step], np.zeros(PS_TRAILING_FRAMES, dtype=bool)])


def _above_room(pcm: bytes, frames: int) -> np.ndarray:
    """Per 10 ms frame (the first ``frames``), whether it stands :data:`PS_ABOVE_ROOM_DB` above
    the room heard in the utterance's first :data:`PS_ROOM_FRAMES` (the pre-roll the endpointer
    keeps from before the speech started): in a quiet room every frame of the words does; with
    people talking nearby their words in the pre-roll and the hangover do not.

    All True when the start is not clearly quieter than the loudest frame (no pre-roll of room
    to go by, e.g. audio handed over without one).
    """
    level = _frame_levels(pcm)[:frames]
    out = np.ones(frames, dtype=bool)
    out[: len(level)] = _stands_out(level)
    return out


def _stands_out(level: np.ndarray) -> np.ndarray:
    """:func:`_above_room` for frame levels (dBFS) already measured."""
    if len(level) <= PS_ROOM_FRAMES:
        return np.ones(len(level), dtype=bool)
    room = float(np.percentile(level[:PS_ROOM_FRAMES], 90))
    if room > level.max() - PS_ROOM_BELOW_SPEECH_DB:
        return np.ones(len(level), dtype=bool)
    return level >= room + PS_ABOVE_ROOM_DB


def _gate_talk(pcm: bytes) -> bytes:
    """The utterance with other people's talk turned down by :data:`PS_TALK_GATE_DB` wherever
    it does not stand out of the room heard in the pre-roll (:func:`_above_room`), keeping
    :data:`PS_TALK_GATE_KEEP_FRAMES` around the patient's words; unchanged where the room
    is quieter than :data:`PS_TALKING_ROOM_DB` (a quiet room).

    The pre-roll, the hangover and the fixed tail (:func:`_fixed_tail`) of an answer given in
    background talk are talk: the grammar's longer phrases absorbed it, so a short "yes" or
    "no" was heard as "i need a doctor", "pardon" or "louder" at 0.8-0.99, and the words that
    fitted the talk best became the confidence's yardstick. Turned down, the talk around the
    words is scored as the quiet it stands for. bench/asr.py, background talk at SNR 10 dB,
    40 cases per voice (320 utterances per split), dev / held-out, before -> with the gate and
    the two-hearing check of :meth:`PocketSphinxRecogniser.finish`: right answers 0.54 / 0.50 ->
    0.58 / 0.61; "yes" heard as yes 84 of 136 -> 93 of 151 and 86 of 157 -> 101 of 133; commands
    the patient did not give 57 / 73 -> 32 / 41, the doctor called among them 31 / 43 -> 17 / 19;
    real commands 22 / 17 -> 21 / 25; no wrong answer stored. The gate alone gave 0.60 / 0.60,
    but at 20 cases per voice a held-out "no" was heard as "that's right" (0.99) and an answer
    stored wrong, 1 in 160. Set on the dev voices among -15 dB (8 frames kept) and -30 dB (5 and
    10 frames).
    """
    level = _frame_levels(pcm)
    if len(level) <= PS_ROOM_FRAMES or np.percentile(level, 10) < PS_TALKING_ROOM_DB:
        return pcm
    words = _stands_out(level)
    if words.all() or not words.any():
        return pcm  # no room to go by, or nothing stands out of it: nothing to tell apart
    keep = words.copy()
    for shift in range(1, PS_TALK_GATE_KEEP_FRAMES + 1):
        keep[shift:] |= words[:-shift]
        keep[:-shift] |= words[shift:]
    gain = np.repeat(np.where(keep, 1.0, 10 ** (PS_TALK_GATE_DB / 20)), _FRAME_BYTES // 2)
    # a 5 ms ramp at each edge, so the gate does not click (a click is a consonant to the model)
    gain = np.convolve(gain, np.ones(80) / 80, mode="same")
    samples = np.frombuffer(pcm, dtype="<i2").astype(np.float64)
    samples[: len(gain)] *= gain
    return np.clip(np.round(samples), -32768, 32767).astype("<i2").tobytes()


def _frame_levels(pcm: bytes) -> np.ndarray:
    """Level (dBFS) of each whole 10 ms frame."""
    power = frame_powers(np.frombuffer(pcm, dtype="<i2")) / 32768.0**2
    return 10 * np.log10(np.maximum(power, 1e-10))


def _cost(score: float, voiced: np.ndarray) -> float:
    """A path score (pocketsphinx's logmath.exp of log base 1.0001) as cost per voiced frame."""
    return -math.log(score) * 1000 / voiced.sum() if score > 0 else math.inf


def _sigmoid(x: float) -> float:
    """Logistic function, clamped so that exp never overflows."""
    return 1 / (1 + math.exp(-max(-50.0, min(50.0, x))))


def _voiced_frames(pcm: bytes, above_floor_db: float | None = None) -> np.ndarray:
    """Per 10 ms frame (pocketsphinx's frame rate), whether it holds speech rather than silence.

    Voiced means within 30 dB of the utterance's loudest frame and above -55 dBFS, and, given
    ``above_floor_db``, that far above the utterance's quietest tenth (what is left of a noise
    that was subtracted: see :meth:`PocketSphinxRecogniser.finish`).
    """
    level = _frame_levels(pcm)
    if len(level) == 0:
        return np.zeros(0, dtype=bool)
    voiced = (level >= level.max() - 30) & (level >= -55)
    if above_floor_db is not None:
        voiced &= level >= np.percentile(level, 10) + above_floor_db
    return voiced


# --- Vosk ------------------------------------------------------------------------------------


class VoskRecogniser:
    """Vosk (Kaldi) with a model directory and a JSON phrase-list grammar per question."""

    name = "vosk"

    def __init__(self, model_path: str | Path, language: str) -> None:
        try:
            import vosk
        except ImportError as exc:
            raise AsrUnavailable(f"vosk is not installed ({exc})") from None
        vosk.SetLogLevel(-1)
        path = Path(model_path)
        if not path.is_dir():
            raise AsrUnavailable(f"vosk model {path} does not exist")
        try:
            self._model = vosk.Model(str(path))
        except Exception as exc:  # vosk raises a bare Exception for a model it cannot load
            raise AsrUnavailable(f"vosk model {path} cannot be loaded ({exc})") from None
        self._vosk = vosk
        self.language = language
        self.model_path = path
        self._recogniser = None
        self._grammar: Grammar | None = None
        #: Vosk's JSON results for the segments of the current utterance
        self._segments: list[str] = []
        #: phrases that are a whole answer once heard (partial results say so)
        self._final: frozenset[str] = frozenset()

    def set_grammar(
        self,
        phrases: Sequence[str],
        meaning: Callable[[str], Hashable] | None = None,
        lead_ins: Sequence[str] = (),
        fillers: Sequence[str] = (),
        taken_as_heard: bool = False,
    ) -> Grammar:
        """Make a recogniser limited to the phrases the model knows (plus "[unk]").

        ``meaning`` is not needed: Vosk's own word confidences tell confusable words apart.
        ``taken_as_heard`` changes nothing: Vosk hears each utterance one way.
        """
        grammar = build_grammar(
            phrases, lambda w: self._model.vosk_model_find_word(w) >= 0, self.name, lead_ins, fillers, meaning
        )
        if not grammar.phrases:
            raise ValueError("a grammar needs at least one phrase the recogniser knows")
        self._recogniser = self._vosk.KaldiRecognizer(self._model, SAMPLE_RATE, to_vosk(grammar))
        self._recogniser.SetWords(True)
        self._grammar = grammar
        self._final = final_phrases(grammar.phrases, meaning or (lambda p: p))
        self.reset()
        return grammar

    def reset(self) -> None:
        """Drop any utterance in progress."""
        if self._recogniser is not None:
            self._recogniser.Reset()
        self._segments = []

    def accept(self, pcm: bytes) -> Recognition | None:
        """Decode more audio; Vosk may close a segment at its own pause detection. The partial
        result is the text of the whole utterance so far."""
        if self._recogniser is None:
            raise RuntimeError("set_grammar must be called before recognising")
        if self._recogniser.AcceptWaveform(pcm):
            self._segments.append(self._recogniser.Result())
            partial = ""
        else:
            partial = json.loads(self._recogniser.PartialResult()).get("partial", "")
        text = " ".join([*(json.loads(s).get("text", "") for s in self._segments), partial]).split()
        heard = " ".join(text)
        complete = self._grammar is not None and self._grammar.core(heard) in self._final
        return Recognition(heard, 0.0, final=False, complete=complete) if heard else None

    def finish(self) -> Recognition:
        """End the utterance and combine its segments (see :func:`vosk_recognition`)."""
        if self._recogniser is None:
            return Recognition("", 0.0)
        segments = [*self._segments, self._recogniser.FinalResult()]
        self._segments = []
        result = vosk_recognition(segments)
        if self._grammar is not None and self._grammar.core(result.text) not in self._grammar.phrases:
            # Vosk's grammar lets phrases follow one another, and a model without "[unk]" (the
            # Korean one) forces any sentence into a run of them ("셋 셋 혼자", each word 0.65
            # sure): only one phrase, maybe after a lead-in, is something a patient answered
            return Recognition(result.text, 0.0)
        return result


def vosk_recognition(results: Sequence[str]) -> Recognition:
    """One utterance from Vosk's JSON results (``{"text": ..., "result": [{"word", "conf"}...]}``).

    The confidence is the lowest word confidence; any "[unk]" makes it 0, because the unknown
    word may have been "not" in "not independent".
    """
    texts: list[str] = []
    confidences: list[float] = []
    for raw in results:
        result = json.loads(raw)
        if result.get("text"):
            texts.append(result["text"])
        confidences += [float(w.get("conf", 0.0)) for w in result.get("result", [])]
    text = " ".join(texts).strip()
    if not text or "[unk]" in text.split() or not confidences:
        return Recognition(text, 0.0)
    return Recognition(text, min(confidences))


# --- choosing one ----------------------------------------------------------------------------


def open_recogniser(language: str, model_path: str | Path | None = None) -> Recogniser:
    """The best recogniser for ``language`` on this machine.

    Vosk with the model ``model_path`` (a model or a folder of models, see
    :func:`kiosk.speech.models.find_model`) or an installed one;
    else PocketSphinx for English; else :class:`AsrUnavailable` saying why voice in is off.
    """
    from kiosk.speech.models import find_model

    path = find_model(language, model_path)
    if path is not None:
        return VoskRecogniser(path, language)
    return PocketSphinxRecogniser(language)
