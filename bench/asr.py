"""Voice answers in the room: a matrix of patients' voices × room conditions, through the real
path (endpointer → recogniser → matcher → :class:`VoiceChannel`), with the confirmation the
session asks for modelled honestly.

For every voice and condition, simulated patients answer Barthel questions (option labels,
synonyms, numbers, "the first one", natural answers such as "I need a lot of help"), give
commands, and say things that are not answers ("um", "what?", a cough, "is it time for lunch
yet"). Each utterance is spoken by espeak-ng in that patient's voice, put in the room
(``bench/_rooms.py``: white or babble noise at an SNR, reverb, telephone band, -20 dB, a
long silence first), and fed as one continuous microphone stream, the room's noise going on
between answers and the channel muted while the kiosk speaks. A patient gets two attempts. When
the channel asks for confirmation, the patient answers "yes" (in a few natural forms) only if the
heard option is the one they meant, else "no", and that reply goes through the recogniser too:
an answer is STORED only when confirmed (or sent without needs_confirmation).

Per condition, JSON: ``right`` (stored right, or the right command, within two attempts),
``right_first``, ``wrong_stored`` (an answer stored as another option), ``non_answers_stored``
(a non-answer stored as an option), ``wrong_rate`` (both, over all utterances: target <= 0.005),
``wrong_commands`` (a command the patient did not give, e.g. the doctor called), ``asked_again``,
``confirmations``, ``asked_to_press`` (a spoken yes to "Is that right?" the room was too loud
to take: the kiosk asks for a press, which this patient does not give), ``asked_to_press_right``
(of those, the answer heard was the one meant), ``cut_off`` (utterances run to the 10 s limit:
target 0 in steady noise at SNR >= 10 dB), ``rtf``, ``speech_end_to_answer_ms``, and
``unconfirmed_wrong_by_confidence``: the wrong-stored rate if answers at or above a confidence
were stored without asking (how :data:`kiosk.speech.voice.CONFIRM_BELOW` was chosen). Targets for
``right``: >= 0.8 clean, >= 0.5 at SNR 10 dB.

Voices: ``dev`` tunes (thresholds, confusable words, grammar), ``held_out`` only reports. None is
the kiosk's own voice. mbrola voices (``mbrola-us1`` ...) are in Debian's contrib section, which
this machine's sources do not carry; where they are installed, pass e.g. ``--voices mb-us1:150``.

    uv run python bench/asr.py [--voices dev|held_out|all|VOICE:WPM ...] [--conditions NAME ...]
                               [--quick] [--cases N] [--vad energy|webrtc|silero] [--cache DIR]
                               [--recogniser pocketsphinx|whisper] [--languages en es fr de]
                               [--hard] [--voices-per-language N]

``--hard``: issue 33's rooms (quiet, 20 dB noise, RT60 1 and 1.5 s, talk at 7 and 5 dB);
``--languages es fr de`` (Whisper): 4 espeak-ng voices each (``_asr_cases.OTHER_VOICES``);
``--voices-per-language N``: the first N voices per split (a bounded run). Also reported:
``right_option_stored``, ``false_calls``, ``cpu_ms_per_utterance``, ``max_rss_mb`` and
``speech_end_to_answer_wall_ms`` (the final decode's wall time, the machine's other work in it).

``--vad webrtc`` needs ``uv pip install webrtcvad-wheels``; ``--vad silero`` needs onnxruntime and
silero-vad's ONNX model (see ``bench/_vads.py``): neither is a kiosk dependency.

Figures, dated with the command that produced them: bench/RESULTS.md. Why the recogniser's
constants have their values: docs/speech-tuning.md.
"""

from __future__ import annotations

import argparse
import json
import random
import resource
import sys
import tempfile
import zlib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _rooms as rooms
from _asr_cases import (
    BABBLE_TALKERS,
    BABBLE_TEXT,
    CONDITIONS,
    HARD_CONDITIONS,
    OTHER_VOICES,
    QUICK_CONDITIONS,
    SPEECH_LEVEL,
    VOICES,
    Condition,
    language_cases,
    patient_cases,
    yes_no,
)
from _timed import Timed
from _vads import endpointer_factory

from kiosk.core.channels import ChannelInput, Command
from kiosk.core.questionnaire import load_questionnaire
from kiosk.speech.asr import PocketSphinxRecogniser, open_whisper
from kiosk.speech.audio import SAMPLE_RATE, feed_samples, read_wav
from kiosk.speech.matching import START_WORDS, OptionWords
from kiosk.speech.tts import Synthesiser
from kiosk.speech.voice import VoiceChannel


class Audio:
    """Patients' utterances as 16 kHz samples, synthesised once into a cache folder."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.synthesiser = Synthesiser()

    def say(self, text: str, voice: str, rate: int) -> np.ndarray:
        """``text`` in that voice; "<cough>" is a cough."""
        if text == "<cough>":
            return rooms.cough(np.random.default_rng(zlib.crc32(voice.encode())))  # the same every run
        path = self.folder / f"{voice.replace('/', '_')}-{rate}-{text.replace(' ', '_').replace('?', '')}.wav"
        if not path.exists():
            self.synthesiser.speak_as(text, voice, rate, path)
        return read_wav(path)


class Room:
    """One continuous microphone stream in a condition: gaps of room noise, utterances in it."""

    def __init__(self, condition: Condition, audio: Audio, seed: int) -> None:
        self.condition = condition
        self.rng = np.random.default_rng(seed)
        self.talkers = []
        if condition.noise == "babble":
            self.talkers = [
                np.concatenate([audio.say(t, v, r) for t in BABBLE_TEXT[i:] + BABBLE_TEXT[:i]])
                for i, (v, r) in enumerate(BABBLE_TALKERS)
            ]

    def _noise(self, seconds: float) -> np.ndarray:
        if self.condition.noise == "white":
            return rooms.white_noise(seconds, self.rng)
        return rooms.babble(self.talkers, seconds, self.rng)

    def scene(self, speech: np.ndarray) -> np.ndarray:
        """The speech with quiet (or the room's noise) before and after it."""
        c = self.condition
        speech = rooms.scale_db(speech, 20 * np.log10(SPEECH_LEVEL / np.sqrt(max(rooms.active_power(speech), 1))))
        if c.effect == "reverb":
            speech = rooms.reverberate(speech, c.rt60, self.rng)
        elif c.effect == "telephone":
            speech = rooms.telephone_band(speech)
        elif c.effect == "quiet":
            speech = rooms.scale_db(speech, -20)
        lead = 4.0 if c.effect == "leading_silence" else float(self.rng.uniform(0.6, 1.2))
        before, after = int(lead * SAMPLE_RATE), int(1.2 * SAMPLE_RATE)
        seconds = (before + len(speech) + after) / SAMPLE_RATE
        if c.noise:  # at the SNR against the patients' -20 dBFS speech level
            out = self._noise(seconds) * SPEECH_LEVEL * 10 ** (-c.snr_db / 20)
        else:  # a microphone's own hiss, -75 dBFS
            out = rooms.white_noise(seconds, self.rng) * 32768 * 10 ** (-75 / 20)
        out[before : before + len(speech)] += speech
        return np.clip(np.round(out), -32768, 32767).astype(np.int16)


class Patient:
    """One voice in one room, answering through a real :class:`VoiceChannel`."""

    def __init__(
        self,
        voice: str,
        rate: int,
        condition: Condition,
        audio: Audio,
        vad,
        confirm_below: float,
        seed: int,
        language: str = "en",
        recogniser_name: str = "pocketsphinx",
    ) -> None:
        self.voice, self.rate, self.audio, self.language = voice, rate, audio, language
        self.room = Room(condition, audio, seed)
        self.inputs: list = []
        self.utterances: list = []
        #: end of speech → answer (s): the endpointer's wait (stream time) + the final decode
        self.latency: list[float] = []
        #: the same with the final decode's wall time (the machine's other work included)
        self.latency_wall: list[float] = []
        self.timed: list[Timed] = []
        self.audio_seconds = 0.0
        #: spoken yeses the channel sent as unsure (see VoiceChannel.reply_min_above_room_db)
        self.asked_to_press = 0
        #: ... of which the option heard was the one meant (pressing Yes would have stored it)
        self.asked_to_press_right = 0

        def recogniser(language: str) -> Timed:
            inner = open_whisper(language) if recogniser_name == "whisper" else PocketSphinxRecogniser(language)
            self.timed.append(Timed(inner))
            return self.timed[-1]

        self.channel = VoiceChannel(
            language,
            recogniser_factory=recogniser,
            confirm_below=confirm_below,
            on_utterance=self._heard,
            endpointer_factory=vad,
        )
        self.channel.attach(self.inputs.append)
        self.channel.listen(True)
        # Before the first question the kiosk has listened on its welcome screen ("or say
        # start"), so its endpointer has heard the room (it keeps it across prompts and
        # questions). What it made of the room there is not one of the answers measured.
        start = "Start" if language == "en" else START_WORDS[language][0]
        self.channel.set_question([OptionWords(start)], language)
        for _ in range(2):
            room = self.room.scene(np.zeros(0, dtype=np.int16))
            feed_samples(room, self.channel)
            self.audio_seconds += len(room) / SAMPLE_RATE  # the recogniser's time on it counts too
        self.inputs.clear()
        self.utterances.clear()
        self.latency.clear()
        self.latency_wall.clear()

    def _heard(self, utterance) -> None:
        self.utterances.append(utterance)
        if not utterance.cut_off:
            self.latency.append(utterance.endpoint - utterance.speech_end + self.timed[-1].last_finish)
            self.latency_wall.append(utterance.endpoint - utterance.speech_end + utterance.finish_seconds)

    def say(self, text: str, slower: int = 0) -> ChannelInput | None:
        """The kiosk has just spoken (muted, unmuted); the patient says ``text``; the first answer
        or command the channel sends, if any. The kiosk keeps listening while speech goes on."""
        self.channel.set_muted(True)
        self.channel.set_muted(False)
        self.inputs.clear()
        samples = self.room.scene(self.audio.say(text, self.voice, self.rate - slower))
        feed_samples(samples, self.channel)
        self.audio_seconds += len(samples) / SAMPLE_RATE
        waited = 0.0
        while self.channel.in_speech and waited < 12:
            more = self.room.scene(np.zeros(0, dtype=np.int16))
            feed_samples(more, self.channel)
            waited += len(more) / SAMPLE_RATE
        self.audio_seconds += waited
        return next((i for i in self.inputs if isinstance(i, ChannelInput)), None)

    def question(self, options: list[OptionWords], key: str) -> None:
        """A Barthel question's options become the grammar."""
        self.channel.set_question(options, self.language, scored=True, key=key)

    def answer(self, options: list[OptionWords], text: str, expected, key: int) -> dict:
        """Two attempts at one question, with confirmations; what was stored or done. A declined
        option is told to the channel as the session's ``AnswerNotConfirmed`` does."""
        first = None
        out = {"confirmations": 0, "attempts": 0, "stored": None, "command": None}
        item = f"q{key}"
        for attempt in (1, 2):
            out["attempts"] = attempt
            self.question(options, item)
            got = self.say(text, slower=0 if attempt == 1 else 20)  # a repeat comes slower
            if attempt == 1:
                first = got
            if got is None:
                continue
            if got.command is not None:
                out["command"] = got.command
                if got.command == expected:
                    break
                continue
            if got.needs_confirmation:
                out["confirmations"] += 1
                confirmed = self.confirm(got.option == expected, key)
                if confirmed is False:  # a No heard: the session tells the channel
                    self.channel.declined(item, got.option)
                if not confirmed:
                    continue
            out["stored"] = got.option
            break
        out["first"] = first
        return out

    def confirm(self, meant: bool, key: int) -> bool | None:
        """ "I heard X, is that right?": the patient says yes only if X is what they meant;
        whether the kiosk heard yes (asked once more if it heard neither; None if it never did)."""
        yes, no = yes_no(self.language)
        reply = (yes if meant else no)[key % 4]
        labels = [OptionWords(w) for w in ((yes[0], no[0]) if self.language != "en" else ("Yes", "No"))]
        for _ in range(2):
            self.channel.set_question(labels, self.language, scored=False, confirming=True)
            got = self.say(reply)
            if got is not None and got.option == 1 and got.needs_confirmation:
                # the room was too loud to take a spoken yes: the session asks the patient to
                # press Yes or No, which this voice-only patient does not do
                self.asked_to_press += 1
                self.asked_to_press_right += meant
                return None
            if got is not None and got.option is not None:
                return got.option == 1
            if got is not None and got.command is Command.UNDO:
                return False
        return None


def _p(values: list[float], q: float) -> float | None:
    return round(1000 * sorted(values)[int(q * (len(values) - 1))], 1) if values else None


def run_condition(name: str, voices, cases, audio: Audio, args, language: str = "en") -> dict:
    """Every voice's sample of cases in one condition; the figures."""
    condition = CONDITIONS[name]
    questionnaire = load_questionnaire()
    options_of = {
        item.id: [OptionWords(o.label_in(language), tuple(o.synonyms_in(language))) for o in item.options]
        for item in questionnaire.items
    }
    tally = dict(
        utterances=0,
        answers=0,
        non_answers=0,
        commands=0,
        right=0,
        right_answers=0,
        false_calls=0,
        right_first=0,
        wrong_stored=0,
        non_answers_stored=0,
        wrong_commands=0,
        asked_again=0,
        confirmations=0,
        unresolved=0,
        asked_to_press=0,
        asked_to_press_right=0,
    )
    first_inputs: list[tuple[float, bool]] = []
    latency, latency_wall, cut_off, seconds, audio_seconds, mistakes, finished = [], [], 0, 0.0, 0.0, [], 0
    for v, (voice, rate) in enumerate(voices):
        rng = random.Random(f"{name}/{voice}/{rate}")
        sample = rng.sample(cases, min(args.cases, len(cases)))
        patient = Patient(
            voice,
            rate,
            condition,
            audio,
            endpointer_factory(args.vad, args.silero_onnx),
            args.confirm_below,
            seed=rng.randrange(2**32),
            language=language,
            recogniser_name=args.recogniser,
        )
        for k, (item, text, expected) in enumerate(sample):
            outcome = patient.answer(options_of[item], text, expected, key=k + v)
            kind = "non_answers" if expected is None else "commands" if isinstance(expected, Command) else "answers"
            tally["utterances"] += 1
            tally[kind] += 1
            tally["confirmations"] += outcome["confirmations"]
            first = outcome["first"]
            if first is not None and first.option is not None:
                first_inputs.append((first.confidence or 0.0, first.option == expected))
            right = outcome["stored"] == expected if kind == "answers" else outcome["command"] == expected
            right = right and (kind != "non_answers" or outcome["stored"] is None)
            if outcome["stored"] is not None and outcome["stored"] != expected:
                tally["non_answers_stored" if kind == "non_answers" else "wrong_stored"] += 1
                mistakes.append((voice, item, text, outcome["stored"]))
            if outcome["command"] is not None and outcome["command"] != expected:
                tally["wrong_commands"] += 1
                tally["false_calls"] += outcome["command"] is Command.CALL_DOCTOR
                mistakes.append((voice, item, text, outcome["command"].value))
            if kind != "non_answers":
                tally["right"] += right
                tally["right_answers"] += right and kind == "answers"
                tally["right_first"] += right and outcome["attempts"] == 1
                tally["asked_again"] += outcome["attempts"] > 1
                tally["unresolved"] += outcome["stored"] is None and outcome["command"] != expected
        latency += patient.latency
        latency_wall += patient.latency_wall
        finished += sum(t.finished for t in patient.timed)
        tally["asked_to_press"] += patient.asked_to_press
        tally["asked_to_press_right"] += patient.asked_to_press_right
        cut_off += sum(u.cut_off for u in patient.utterances)
        seconds += sum(t.seconds for t in patient.timed)
        audio_seconds += patient.audio_seconds
        patient.channel.stop()
    n, given = tally["utterances"], tally["answers"] + tally["commands"]
    return {
        **tally,
        "right": round(tally["right"] / max(1, given), 3),
        "right_option_stored": round(tally["right_answers"] / max(1, tally["answers"]), 3),
        "right_first": round(tally["right_first"] / max(1, given), 3),
        "asked_again": round(tally["asked_again"] / max(1, given), 3),
        "wrong_rate": round((tally["wrong_stored"] + tally["non_answers_stored"]) / max(1, n), 4),
        "cut_off": cut_off,
        "rtf": round(seconds / max(audio_seconds, 1e-9), 4),
        "speech_end_to_answer_ms": {"p50": _p(latency, 0.5), "p95": _p(latency, 0.95)},
        "speech_end_to_answer_wall_ms": {"p50": _p(latency_wall, 0.5), "p95": _p(latency_wall, 0.95)},
        "cpu_ms_per_utterance": round(1000 * seconds / max(1, finished), 1),
        "unconfirmed_wrong_by_confidence": {
            str(t): round(sum(1 for c, ok in first_inputs if c >= t and not ok) / max(1, n), 4)
            for t in (0.6, 0.7, 0.8, 0.9, 0.95)
        },
        "mistakes": mistakes[:20],
    }


def main(argv: list[str] | None = None) -> int:
    """Run the matrix and print its JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--voices",
        nargs="+",
        default=["dev", "held_out"],
        help="dev, held_out, all, or VOICE:WPM (any espeak-ng voice)",
    )
    parser.add_argument("--conditions", nargs="+", default=list(CONDITIONS), choices=list(CONDITIONS))
    parser.add_argument("--quick", action="store_true", help="3 dev voices, 4 conditions, 20 cases each")
    parser.add_argument("--cases", type=int, default=40, help="utterances per voice and condition")
    parser.add_argument("--vad", default="energy", choices=["energy", "webrtc", "silero"])
    parser.add_argument("--silero-onnx", help="silero-vad's ONNX model (see bench/_vads.py)")
    parser.add_argument(
        "--confirm-below", type=float, default=None, help="confirm answers below this confidence (default: the kiosk's)"
    )
    parser.add_argument("--cache", type=Path, help="keep synthesised speech here between runs")
    parser.add_argument("--recogniser", default="pocketsphinx", choices=["pocketsphinx", "whisper"])
    parser.add_argument(
        "--languages", nargs="+", default=["en"], choices=["en", *OTHER_VOICES], help="es/fr/de: --recogniser whisper"
    )
    parser.add_argument("--hard", action="store_true", help="issue 33's rooms (quiet, noise, RT60 1-1.5 s, talk)")
    parser.add_argument("--voices-per-language", type=int, default=0, help="a subset of voices per split (0: all)")
    args = parser.parse_args(argv)
    from kiosk.speech.voice import CONFIRM_BELOW

    args.confirm_below = CONFIRM_BELOW if args.confirm_below is None else args.confirm_below
    splits = {"dev": VOICES["dev"], "held_out": VOICES["held_out"]}
    if args.quick:
        splits, args.conditions, args.cases = {"dev": VOICES["dev"][:3]}, QUICK_CONDITIONS, 20
    elif args.voices != ["dev", "held_out"]:
        named = [v for v in args.voices if ":" in v]
        splits = {s: VOICES[s] for s in args.voices if s in VOICES}
        if "all" in args.voices:
            splits = dict(VOICES)
        if named:
            splits["named"] = [(v.split(":")[0], int(v.split(":")[1])) for v in named]
    if args.hard:
        args.conditions = HARD_CONDITIONS
    if args.voices_per_language:
        splits = {s: vs[: args.voices_per_language] for s, vs in splits.items()}
    questionnaire = load_questionnaire()
    report = {
        "goals": {
            "wrong_rate_max": 0.005,
            "right_option_stored_min": {"clean": 0.85, "white_20": 0.75, "reverb_1s": 0.75, "talk_7": 0.55},
            "speech_end_to_answer_ms_max": {"p50": 600, "p95": 900},
        },
        "recogniser": args.recogniser,
        "vad": args.vad,
        "confirm_below": args.confirm_below,
        "cases_per_voice": args.cases,
        "voices": {s: [f"{v}:{r}" for v, r in vs] for s, vs in splits.items()},
        "conditions": {},
    }
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.cache or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        audio = Audio(folder)
        for name in args.conditions:
            report["conditions"][name] = {}
            for language in args.languages:
                if language == "en":
                    cases, by_split = patient_cases(questionnaire), splits
                else:
                    voices = OTHER_VOICES[language][: args.voices_per_language or None]
                    cases, by_split = language_cases(questionnaire, language), {"voices": voices}
                    report["voices"][language] = [f"{v}:{r}" for v, r in voices]
                for split, voices in by_split.items():
                    key = split if language == "en" else language
                    report["conditions"][name][key] = run_condition(name, voices, cases, audio, args, language)
            print(json.dumps({name: report["conditions"][name]}, default=str), file=sys.stderr, flush=True)
    report["max_rss_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)
    json.dump(report, sys.stdout, indent=2, default=str)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
