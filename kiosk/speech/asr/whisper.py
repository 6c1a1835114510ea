"""Whisper (CTranslate2) decoding each whole utterance, with PocketSphinx as the English
end-of-turn detector.

While the patient speaks, the audio goes to PocketSphinx under the question's grammar (English
only: its dictionary is English), whose partial result says when what was heard is already a
whole answer, so the endpointer closes after its short hangover; no Whisper work is done then.
At the endpoint Whisper decodes the utterance once (greedy, prompted with the question's
phrases), and the transcript is checked before anything is made of it:

- no speech (Whisper's own no-speech probability above :data:`WHISPER_NO_SPEECH_MAX`), a poor
  fit (mean token log-probability below :data:`WHISPER_LOGPROB_MIN`), a sound annotation
  ("(coughing)"), a known subtitle hallucination, or more words than the
  voiced audio can hold (:data:`WHISPER_MAX_WORDS_PER_S`: a cough "heard" as a whole answer
  from the prompt) → no answer (confidence 0, or an empty text);
- a command, and any reply acted on without asking back (``taken_as_heard``: a confirmation's
  yes or no), only as a whole phrase of the grammar, maybe after a lead-in: "no that's not what
  I said" is not "yes", and "don't call the doctor" no call;
- an option answer (always asked back on a scored question) may also be said inside a sentence
  ("yes I can do it alone" holds "alone"); a transcript that is none is scored again against the
  option phrases written most like it (forced alignment, :data:`WHISPER_RESCORE_MIN`): "la voz"
  is "la dos" (never a command or a taken-as-heard reply).

The confidence comes from the mean token log-probability (:data:`WHISPER_CONFIDENCE_SCALE`),
on the one scale the matcher's thresholds are set on.
Tuning: docs/speech-tuning.md; measured: bench/asr.py.
"""

from __future__ import annotations

import difflib
import logging
import math
import re
from collections.abc import Callable, Hashable, Sequence
from enum import Enum
from typing import Any

import numpy as np

from kiosk.speech.asr.base import AsrUnavailable, Recognition
from kiosk.speech.asr.levels import gate_talk, voiced_frames
from kiosk.speech.asr.whisper_files import model_folder
from kiosk.speech.audio import SAMPLE_RATE
from kiosk.speech.denoise import reduce_steady_noise
from kiosk.speech.grammar import Grammar, build_grammar
from kiosk.speech.matching import normalise

log = logging.getLogger(__name__)

#: above this no-speech probability an utterance is nothing said
WHISPER_NO_SPEECH_MAX = 0.6
#: below this mean log-probability per token an option answer is not taken (it is asked back
#: anyway) ...
WHISPER_LOGPROB_MIN = -1.5
#: ... nor, below this, a reply acted on at once (a confirmation's yes or no)
WHISPER_REPLY_LOGPROB_MIN = -1.0
#: a transcript that is no answer is decoded again against this many option phrases written
#: most like it ...
WHISPER_RESCORE_SHORTLIST = 3
#: ... and taken as the likeliest of them if its tokens' mean log-probability is at least this
WHISPER_RESCORE_MIN = -3.0
#: the confidence is exp(mean log-probability / this) times (1 - the no-speech probability): a
#: transcript at the floor above is 0.72 sure, one at -0.67 the 0.8 a command needs
WHISPER_CONFIDENCE_SCALE = 3.0
#: more words than this per voiced second is text the prompt put there, not speech
WHISPER_MAX_WORDS_PER_S = 6.0
#: the encoder hears at least this many 10 ms feature frames (the utterance padded with
#: silence): Whisper was trained on 30 s windows and invents more on much shorter ones, while
#: the encoder's cost grows with the window (docs/speech-tuning.md)
WHISPER_MIN_FRAMES = 1000
#: hypotheses kept while decoding (1: greedy)
WHISPER_BEAM = 1
#: CPU threads for one decode (the kiosk's UI and the audio thread share the rest)
WHISPER_THREADS = 1
#: at most this many prompt tokens (Whisper's own limit is 223)
WHISPER_PROMPT_TOKENS = 120
#: words that turn a reply around ("not right"), refusing the detector's second hearing of it
NEGATIONS = frozenset({"no", "not", "nope", "wrong", "incorrect", "isn", "don", "never", "nothing"})
#: what Whisper says over silence and noise, learnt from subtitled video (normalised)
HALLUCINATIONS = frozenset(
    {
        "you",
        "thank you",
        "thanks for watching",
        "thank you for watching",
        "bye",
        "subtitles by the amara org community",
        "gracias",
        "merci",
        "danke",
        "untertitel im auftrag des zdf 2017",
        "sous titrage societe radio canada",
    }
)


class WhisperRecogniser:
    """Whisper (CTranslate2) on each whole utterance; see the module docstring."""

    name = "whisper"
    #: why a better recogniser is not used ("" when none would be)
    fallback = ""

    def __init__(
        self, language: str, detector: Any = None, *, prompt: bool = True, threads: int = WHISPER_THREADS
    ) -> None:
        """``detector``: a recogniser whose partial results end the turn (PocketSphinx for English),
        or None (the endpointer's long hangover). ``prompt``: prime the decoder with the phrases."""
        folder = model_folder(language)
        try:
            import ctranslate2
            import tokenizers
            from faster_whisper.feature_extractor import FeatureExtractor
        except ImportError as exc:
            raise AsrUnavailable(f"the Whisper runtime is not installed ({exc})") from None
        try:
            self._model = ctranslate2.models.Whisper(
                str(folder), device="cpu", compute_type="int8", intra_threads=threads
            )
            self._tokenizer = tokenizers.Tokenizer.from_file(str(folder / "tokenizer.json"))
        except (RuntimeError, ValueError, OSError) as exc:
            raise AsrUnavailable(f"the Whisper model in {folder} cannot be loaded ({exc})") from None
        self._ctranslate2 = ctranslate2
        self._features = FeatureExtractor(feature_size=self._model.n_mels)
        self.language = language
        self.model_path = folder
        self._detector = detector
        self._prompt_on = prompt
        #: see :data:`WHISPER_MIN_FRAMES`
        self.min_frames = WHISPER_MIN_FRAMES
        self._pcm = bytearray()
        self._grammar: Grammar | None = None
        self._meaning: Callable[[str], Hashable] = lambda p: p
        self._taken_as_heard = False
        #: normalised phrase (or lead-in + phrase) → the phrase as written
        self._whole: dict[str, str] = {}
        self._prompt: list[int] = []

        def token(name: str) -> int:
            found = self._tokenizer.token_to_id(name)
            if found is None:
                raise AsrUnavailable(f"the Whisper tokenizer in {folder} has no {name} token")
            return int(found)

        self._start = [token("<|startoftranscript|>")]
        if self._model.is_multilingual:
            self._start += [token(f"<|{language}|>"), token("<|transcribe|>")]
        self._start.append(token("<|notimestamps|>"))
        self._previous = token("<|startofprev|>")
        self._end_of_text = token("<|endoftext|>")

    def set_grammar(
        self,
        phrases: Sequence[str],
        meaning: Callable[[str], Hashable] | None = None,
        lead_ins: Sequence[str] = (),
        fillers: Sequence[str] = (),
        taken_as_heard: bool = False,
    ) -> Grammar:
        """Listen for these phrases: they prime the decoder and are what a transcript may mean;
        the detector (if any) gets the same grammar."""
        grammar = build_grammar(phrases, lambda w: True, self.name, lead_ins, fillers, meaning)
        if not grammar.phrases:
            raise ValueError("a grammar needs at least one phrase")
        if self._detector is not None:
            try:
                self._detector.set_grammar(phrases, meaning, lead_ins, fillers, taken_as_heard)
            except ValueError:  # no phrase in the detector's dictionary: the long hangover
                log.debug("whisper: the end-of-turn detector knows none of %s", phrases[:3])
        self._grammar = grammar
        self._meaning = meaning or (lambda p: p)
        self._taken_as_heard = taken_as_heard
        self._whole = {normalise(p): p for p in grammar.phrases}
        for lead in grammar.lead_ins:
            self._whole.update({normalise(f"{lead} {p}"): p for p in grammar.answers})
        # the answers last, nearest the audio, and kept whole when the prompt is cut to its last
        # WHISPER_PROMPT_TOKENS: a Spanish "Is that right?" with its commands first lost every
        # "Sí." ("sí" was heard as "C.", "es correcto" as "es el médico")
        said = [*(p for p in grammar.phrases if p not in grammar.answers), *grammar.answers]
        words = " ".join(dict.fromkeys(p.capitalize() + "." for p in said))
        ids = self._tokenizer.encode(" " + words, add_special_tokens=False).ids[-WHISPER_PROMPT_TOKENS:]
        self._prompt = [self._previous, *ids] if self._prompt_on else []
        self.reset()
        return grammar

    def reset(self) -> None:
        """Drop any utterance in progress."""
        self._pcm.clear()
        if self._detector is not None:
            self._detector.reset()

    def accept(self, pcm: bytes) -> Recognition | None:
        """Keep the audio; the detector's partial result says whether a whole answer was heard."""
        if self._grammar is None:
            raise RuntimeError("set_grammar must be called before recognising")
        self._pcm += pcm
        if self._detector is None:
            return None
        try:
            partial = self._detector.accept(pcm)
        except RuntimeError:  # the detector had no phrase of this grammar
            return None
        return Recognition("", 0.0, final=False, complete=bool(partial and partial.complete))

    def finish(self) -> Recognition:
        """Decode the utterance and check the transcript (see the module docstring)."""
        pcm = bytes(self._pcm)
        self._pcm.clear()
        if self._grammar is None or len(pcm) < 2 * SAMPLE_RATE // 10:
            if self._detector is not None:
                self._detector.close()
            return Recognition("", 0.0)
        pcm = self._front_end(pcm)
        encoded, frames = self._encode(pcm)
        text, logprob, no_speech = self._generate(encoded, len(pcm) / 2 / SAMPLE_RATE)
        result = self._judge(pcm, encoded, frames, text, logprob, no_speech)
        if self._detector is None:
            return result
        meaning = self._meaning(result.text)
        if result.confidence > 0 and (_is_command(meaning) or self._taken_as_heard and _is_option(meaning)):
            return self._agreed(result, meaning)  # acted on at once
        if result.confidence > 0 and _is_option(meaning):
            self._detector.close()
            return result
        return self._second_hearing(result, normalise(text))

    def _agreed(self, result: Recognition, option: Hashable) -> Recognition:
        """A command or a reply acted on at once (English): Whisper's hearing stands only where
        the detector heard the same, unless it is itself a refusal (its phrases hold a negation:
        declining stores nothing). Whisper prompted with the commands heard "I need help" in
        white noise as "I need a doctor". The kiosk's own voice saying "not right" came out
        of Whisper as "That's right." (0.94); PocketSphinx heard "wrong"."""
        assert self._grammar is not None and self._detector is not None
        second = self._detector.finish()
        mine = {w for p in self._grammar.phrases if self._meaning(p) == option for w in normalise(p).split()}
        if mine & NEGATIONS or (second.confidence > 0 and self._meaning(second.text) == option):
            return result
        log.debug("whisper: %r, but the detector heard %r", result.text, second.text)
        return Recognition(result.text, 0.0)

    def _second_hearing(self, result: Recognition, heard: str) -> Recognition:
        """Where Whisper heard no answer, the detector's own hearing of an option (PocketSphinx,
        with its own checks), unless Whisper's transcript holds a word only another option's
        phrases have, or, for a reply taken at once, a negation (:data:`NEGATIONS`: "yes not right"
        is no yes); a reply taken at once only if it declines (its phrases hold a negation).
        tiny.en hears espeak-ng's "that's right" as "next slide"."""
        assert self._grammar is not None and self._detector is not None
        second = self._detector.finish()
        option = self._meaning(second.text) if second.confidence > 0 else None
        if not _is_option(option):
            return result
        mine = {w for p in self._grammar.phrases if self._meaning(p) == option for w in normalise(p).split()}
        if self._taken_as_heard and not mine & NEGATIONS:
            # a reply acted on at once on the detector's word alone only if it declines: in a
            # reverberant room "no it isn't", which Whisper heard as "and now you do that", was
            # "yes it is" (0.98) to PocketSphinx, and stored a wrong answer
            log.debug("whisper: %r; the detector alone heard %r: not taken", heard, second.text)
            return result
        others = {w for p in self._grammar.phrases if self._meaning(p) != option for w in normalise(p).split()}
        if self._taken_as_heard:  # a reply acted on at once: any negation refuses it
            others |= NEGATIONS
        others -= mine
        if others & set(heard.split()):
            log.debug("whisper: %r contradicts the detector's %r", heard, second.text)
            return result
        log.debug("whisper: %r; the detector heard %r (%.2f)", heard, second.text, second.confidence)
        return second

    @staticmethod
    def _front_end(pcm: bytes) -> bytes:
        """The utterance as PocketSphinx's own scoring gets it: a steady noise subtracted, else
        other people's talk around the patient's words turned down (each leaves a quiet room's
        audio as it is)."""
        cleaned = reduce_steady_noise(pcm)
        return gate_talk(pcm) if cleaned is pcm else cleaned

    def transcribe(self, pcm: bytes) -> tuple[str, float, float]:
        """Whisper's transcript of 16 kHz int16 audio, its mean token log-probability and its
        no-speech probability."""
        encoded, _ = self._encode(pcm)
        return self._generate(encoded, len(pcm) / 2 / SAMPLE_RATE)

    def _encode(self, pcm: bytes) -> tuple[Any, int]:
        """The encoder's output for the utterance, and its number of feature frames."""
        audio = np.frombuffer(pcm, dtype="<i2").astype(np.float32) / 32768
        # padded with silence as Whisper's own 30 s windows are, not with zero features
        hop = SAMPLE_RATE // 100
        audio = np.concatenate([audio, np.zeros(max(0, self.min_frames * hop - len(audio)), np.float32)])
        features = self._features(audio)
        features = np.ascontiguousarray(features[None, :, : features.shape[-1] - features.shape[-1] % 2])
        return self._model.encode(self._ctranslate2.StorageView.from_array(features)), features.shape[-1]

    def _generate(self, encoded: Any, seconds: float) -> tuple[str, float, float]:
        result = self._model.generate(
            encoded,
            [[*self._prompt, *self._start]],
            beam_size=WHISPER_BEAM,
            max_length=len(self._prompt) + len(self._start) + int(8 + 5 * seconds),
            return_scores=True,
            return_no_speech_prob=True,
            suppress_blank=True,
        )[0]
        ids = [t for t in result.sequences_ids[0] if t < self._end_of_text]
        return self._tokenizer.decode(ids).strip(), float(result.scores[0]), float(result.no_speech_prob)

    def _judge(self, pcm: bytes, encoded: Any, frames: int, text: str, logprob: float, no_speech: float) -> Recognition:
        plain = _once(_collapse(normalise(re.sub(r"[\(\[\*♪][^\)\]\*♪]*[\)\]\*♪]?", " ", text))))
        confidence = self._confidence(logprob, no_speech)
        log.debug("whisper: %r logprob %.2f no-speech %.2f", text, logprob, no_speech)
        if not plain or no_speech > WHISPER_NO_SPEECH_MAX or plain in HALLUCINATIONS:
            return Recognition("", 0.0)
        if self._too_many_words(pcm, plain):
            return Recognition(plain, 0.0)
        floor = WHISPER_REPLY_LOGPROB_MIN if self._taken_as_heard else WHISPER_LOGPROB_MIN
        sure = confidence if logprob >= floor else 0.0
        whole = self._whole.get(plain)
        if whole is not None:
            return Recognition(plain, sure)
        meaning = self._meaning(plain)
        if self._taken_as_heard or _is_command(meaning):
            return Recognition(plain, 0.0)  # a command or a reply taken at once: whole phrases only
        if _is_option(meaning):
            return Recognition(plain, sure)  # an option inside a sentence: asked back
        best, best_logprob = self._rescore(encoded, frames, plain)
        if best is not None:
            log.debug("whisper: %r rescored as %r (%.2f)", plain, best, best_logprob)
            # its fit against the free transcript's, as PocketSphinx's against free phones
            return Recognition(best, self._confidence(best_logprob - logprob, no_speech))
        return Recognition(plain, sure)

    @staticmethod
    def _confidence(logprob: float, no_speech: float) -> float:
        """From the mean log-probability; the no-speech probability only gates (a short "two"
        came with 0.3 of it)."""
        return math.exp(min(0.0, logprob) / WHISPER_CONFIDENCE_SCALE) if no_speech <= WHISPER_NO_SPEECH_MAX else 0.0

    def _rescore(self, encoded: Any, frames: int, plain: str) -> tuple[str | None, float]:
        """The option phrase, among the :data:`WHISPER_RESCORE_SHORTLIST` written most like the
        transcript, that Whisper finds likeliest for the audio (forced alignment: the mean
        log-probability of its tokens), if at least :data:`WHISPER_RESCORE_MIN`."""
        assert self._grammar is not None
        alike = sorted(self._grammar.answers, key=lambda p: difflib.SequenceMatcher(None, plain, normalise(p)).ratio())[
            -WHISPER_RESCORE_SHORTLIST:
        ]
        if not alike:
            return None, 0.0
        tokens = [self._tokenizer.encode(" " + p, add_special_tokens=False).ids for p in alike]
        batch = np.repeat(np.asarray(encoded), len(alike), axis=0)
        results = self._model.align(
            self._ctranslate2.StorageView.from_array(np.ascontiguousarray(batch)),
            self._start,
            tokens,
            [frames] * len(alike),
        )
        scored = [
            (sum(math.log(max(p, 1e-9)) for p in r.text_token_probs) / max(1, len(r.text_token_probs)), phrase)
            for phrase, r in zip(alike, results, strict=True)
        ]
        best_logprob, best = max(scored)
        return (best, best_logprob) if best_logprob >= WHISPER_RESCORE_MIN else (None, 0.0)

    def _too_many_words(self, pcm: bytes, plain: str) -> bool:
        voiced = int(voiced_frames(pcm).sum())
        seconds = max(voiced / 100, 0.25)
        return len(plain.split()) > WHISPER_MAX_WORDS_PER_S * seconds + 1


def _is_option(meaning: Hashable) -> bool:
    """Whether a phrase's meaning is an option number (see ``Matcher.meaning``)."""
    return isinstance(meaning, int) and not isinstance(meaning, bool)


def _is_command(meaning: Hashable) -> bool:
    """Whether a phrase's meaning is a command (an enum member; options are numbers, anything
    else is the phrase itself)."""
    return isinstance(meaning, Enum)


def _once(plain: str) -> str:
    """A transcript that is one phrase said over and over, said once: Whisper loops on a short
    answer in a reverberant room ("yes yes yes" from one "yes"), and a repeated phrase means what
    it means once ("no no" is no)."""
    words = plain.split()
    for n in range(1, len(words) // 2 + 1):
        if len(words) % n == 0 and words == words[:n] * (len(words) // n):
            return " ".join(words[:n])
    return plain


def _collapse(plain: str) -> str:
    """The transcript with a phrase said again and again kept once: Whisper loops on a short
    answer ("no it isn't no it isn't", "no no no no"); a word said twice ("no no") is left as said."""
    words = plain.split()
    for n in range(len(words) // 2, 0, -1):
        times = 2 if n > 1 else 3
        i = 0
        while i + times * n <= len(words):
            if all(words[i : i + n] == words[i + k * n : i + (k + 1) * n] for k in range(1, times)):
                j = i + n
                while words[j : j + n] == words[i : i + n]:
                    j += n
                words = words[: i + n] + words[j:]
            i += 1
    return " ".join(words)
