"""Speech recognition benchmark: accuracy, false accepts, real-time factor and latency.

For every Barthel question and every recogniser available here (pocketsphinx for English;
vosk per language when a model is installed or ``KIOSK_VOSK_MODEL`` is set), espeak-ng speaks
the answers a patient may give (each option's synonyms, number words, commands) and phrases that
are not answers; each WAV goes through the real audio pipeline (endpointer → recogniser →
matcher). Prints one JSON document:

- ``accuracy``: answers matched to the right option/command; ``wrong``: matched to another
  one (the dangerous error), of which ``invented_answers`` were taken as another *option* (the
  rest as a command); ``rejected``: heard but not taken (the patient is asked again);
- ``false_accepts``: non-answers taken as an answer or command;
- ``rtf``: recogniser processing time / audio duration (goal < 0.2);
- ``finish_ms``: endpoint decision → result; ``speech_end_to_answer_ms``: end of speech →
  result (goal < 300 ms), which adds the silence the endpointer waited for: the short hangover
  when the recogniser's partial result was already a whole answer (``complete``), the long one
  otherwise (``incomplete``, the patient may still be in mid-answer); ``complete_share`` is how
  many utterances ended early.

    uv run python bench/asr.py [--languages en es fr] [--items N] [--hangover-ms MS]
                               [--complete-hangover-ms MS]
"""

from __future__ import annotations

import argparse
import functools
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

from kiosk.questionnaire import load_questionnaire
from kiosk.speech.asr import AsrUnavailable, PocketSphinxRecogniser, VoskRecogniser
from kiosk.speech.audio import EndpointerSettings, UtterancePipeline, feed_wav
from kiosk.speech.matching import COMMAND_PHRASES, NUMBER_FORMS, ORDINALS, CARDINALS, Matcher
from kiosk.speech.models import find_model
from kiosk.speech.tts import Synthesiser
from kiosk.speech.voice import option_words

#: things people say at a kiosk that are not answers (per language)
NOT_ANSWERS = {
    "en": ["hello", "good morning", "the weather is nice today", "seven", "television",
           "I am fine", "my name is John", "banana split", "what time is it", "where is my coat"],
    "es": ["hola", "buenos días", "hace buen tiempo hoy", "siete", "televisión", "estoy bien",
           "me llamo Juan", "qué hora es", "dónde está mi abrigo", "plátano"],
    "fr": ["bonjour", "il fait beau aujourd'hui", "sept", "télévision", "je vais bien",
           "je m'appelle Jean", "quelle heure est-il", "où est mon manteau", "banane", "merci"],
}


class _Timed:
    """Wraps a recogniser to add up the processor time it spends."""

    def __init__(self, inner) -> None:
        self.inner, self.seconds = inner, 0.0

    def reset(self) -> None:
        """Forward."""
        self.inner.reset()

    def accept(self, pcm: bytes):
        """Forward, timed."""
        began = time.perf_counter()
        try:
            return self.inner.accept(pcm)
        finally:
            self.seconds += time.perf_counter() - began

    def finish(self):
        """Forward, timed."""
        began = time.perf_counter()
        try:
            return self.inner.finish()
        finally:
            self.seconds += time.perf_counter() - began


#: the kiosk's own espeak-ng synthesiser, made once (it lists espeak-ng's voices)
_synthesiser = functools.cache(Synthesiser)


def _say(folder: Path, text: str, language: str) -> Path:
    path = folder / f"{language}-{abs(hash(text))}.wav"
    if not path.exists():
        _synthesiser().synthesise(text, language, path)
    return path


def _answers(options, language: str) -> list[tuple[str, object]]:
    """(utterance, expected option number or Command) a patient may say for this question."""
    cases: list[tuple[str, object]] = []
    for option in options:
        cases += [(s, option.number) for s in option.synonyms]
    for number in range(1, len(options) + 1):
        for form in NUMBER_FORMS[language][:3]:
            if "{n}" in form:
                cases.append((form.format(n=CARDINALS[language][number - 1][0]), number))
        cases.append((NUMBER_FORMS[language][-1].format(o=ORDINALS[language][number - 1][0]), number))
    for command, phrases in COMMAND_PHRASES[language].items():
        cases.append((phrases[0], command))
    return cases


def _p50_ms(seconds: list[float]) -> float | None:
    return round(1000 * statistics.median(seconds), 1) if seconds else None


def run(backend_name: str, make, language: str, items, folder: Path, settings: EndpointerSettings) -> dict:
    """Every question's answers and non-answers through one recogniser; the figures as a dict."""
    recogniser = make(language)
    timed = _Timed(recogniser)
    results: list = []
    pipeline = UtterancePipeline(timed, results.append, settings)
    right = wrong = invented = rejected = false_accepts = n_not = 0
    audio_seconds = 0.0
    finish = []
    #: end of speech → result (s), for utterances closed early (complete) and late
    latency: dict[bool, list[float]] = {True: [], False: []}
    mistakes = []
    missed: list[str] = []
    for item in items:
        options = option_words([_Opt(o, language) for o in item.options])
        matcher = Matcher(options, language)
        recogniser.set_grammar(matcher.phrases(), matcher.meaning)
        cases = _answers([_Opt(o, language) for o in item.options], language)
        cases += [(text, None) for text in NOT_ANSWERS[language]]
        for text, expected in cases:
            results.clear()
            audio_seconds += feed_wav(_say(folder, text, language), pipeline) + 1.0
            finish += [u.finish_seconds for u in results]
            for u in results:
                latency[u.complete].append(u.endpoint - u.speech_end + u.finish_seconds)
            got = None
            for utterance in results:
                match = matcher.match(utterance.result.text, utterance.result.confidence)
                if match.matched:
                    got = match.option if match.option is not None else match.command
                    break
            if expected is None:
                n_not += 1
                if got is not None:
                    false_accepts += 1
                    mistakes.append((item.id, text, str(got)))
            elif got == expected:
                right += 1
            elif got is None:
                rejected += 1
                missed.append(text)
            else:
                wrong += 1
                invented += isinstance(got, int)
                mistakes.append((item.id, text, str(got)))
    answers = right + wrong + rejected
    finish_ms = sorted(1000 * f for f in finish)
    return {
        "backend": backend_name,
        "language": language,
        "answers": answers,
        "accuracy": round(right / answers, 3),
        "wrong": round(wrong / answers, 3),
        "invented_answers": round(invented / answers, 3),
        "rejected": round(rejected / answers, 3),
        "not_answers": n_not,
        "false_accepts": round(false_accepts / n_not, 3),
        "rtf": round(timed.seconds / audio_seconds, 4),
        "finish_ms": {"p50": round(statistics.median(finish_ms), 1),
                      "p95": round(finish_ms[int(0.95 * (len(finish_ms) - 1))], 1),
                      "max": round(finish_ms[-1], 1)},
        "speech_end_to_answer_ms": {
            "p50": _p50_ms(latency[True] + latency[False]),
            "complete_p50": _p50_ms(latency[True]),
            "incomplete_p50": _p50_ms(latency[False]),
            "complete_share": round(len(latency[True]) / max(1, len(latency[True]) + len(latency[False])), 3),
        },
        "mistakes": mistakes,
        "rejected_most": sorted(set(missed), key=missed.count, reverse=True)[:12],
    }


class _Opt:
    """An option in one language, shaped like the session's PromptOption."""

    def __init__(self, option, language: str) -> None:
        self.number = option.number
        self.label = option.label_in(language)
        self.synonyms = option.synonyms_in(language)


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print its JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--languages", nargs="+", default=["en", "es", "fr"])
    parser.add_argument("--items", type=int, default=10, help="how many questions (default all)")
    parser.add_argument("--hangover-ms", type=int, default=EndpointerSettings().hangover_ms,
                        help="the endpointer's end-of-speech silence mid-answer (default: the kiosk's)")
    parser.add_argument("--complete-hangover-ms", type=int, default=EndpointerSettings().complete_hangover_ms,
                        help="its silence after a whole answer (default: the kiosk's)")
    args = parser.parse_args(argv)
    questionnaire = load_questionnaire()
    items = questionnaire.items[: args.items]
    settings = EndpointerSettings(hangover_ms=args.hangover_ms, complete_hangover_ms=args.complete_hangover_ms)
    report = {"goals": {"rtf": 0.2, "speech_end_to_answer_ms": 300}, "hangover_ms": settings.hangover_ms,
              "complete_hangover_ms": settings.complete_hangover_ms, "runs": [], "skipped": []}
    with tempfile.TemporaryDirectory() as tmp:
        for language in args.languages:
            backends = []
            if language == "en":
                backends.append(("pocketsphinx", PocketSphinxRecogniser))
            model = find_model(language)
            if model is not None:
                backends.append(("vosk", lambda lang, model=model: VoskRecogniser(model, lang)))
            else:
                report["skipped"].append({"backend": "vosk", "language": language,
                                          "reason": "no vosk model installed (kiosk models install)"})
            for name, make in backends:
                try:
                    report["runs"].append(run(name, make, language, items, Path(tmp), settings))
                except AsrUnavailable as exc:
                    report["skipped"].append({"backend": name, "language": language, "reason": str(exc)})
    json.dump(report, sys.stdout, indent=2, ensure_ascii=False)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
