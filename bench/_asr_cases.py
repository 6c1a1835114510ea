"""What ``bench/asr.py`` plays: the patients' voices, the rooms, and what each patient says.

Data only (and :func:`patient_cases`, which expands it per question), so the bench's loop reads
apart from the matrix it runs.
"""

from __future__ import annotations

from dataclasses import dataclass

from kiosk.core.channels import Command
from kiosk.speech.matching import spoken_label

#: patients' voices (espeak-ng voice+variant, words per minute); never the kiosk's own en-us at 160
VOICES = {
    "dev": [
        ("en-us+m3", 130),
        ("en+f2", 170),
        ("en-gb+klatt", 150),
        ("en+croak", 120),
        ("en-us+f4", 185),
        ("en-gb-scotland+m7", 145),
        ("en+grandpa", 115),
        ("en-us+whisperf", 150),
    ],
    "held_out": [
        ("en+m5", 140),
        ("en-us+f3", 160),
        ("en+klatt3", 125),
        ("en-gb-x-rp+m2", 180),
        ("en+f5", 110),
        ("en-029+m4", 155),
        ("en-us+aunty", 135),
        ("en+whisper", 165),
    ],
}
#: other people talking in the ward, for babble (never a patient's voice)
BABBLE_TALKERS = [("en-gb+m1", 170), ("en-us+f1", 180), ("en+m6", 160), ("en-gb-x-rp+f3", 175), ("en-us+m8", 165)]
BABBLE_TEXT = [
    "I told her the appointment was moved to Thursday afternoon but she did not listen",
    "Could you bring the trolley round to bed twelve when you have a moment please",
    "The pharmacy said the new tablets will be ready after the lunch round",
    "We went to the seaside last summer and the weather was lovely all week",
    "Has anyone seen the blood pressure cuff from the side room this morning",
]


#: every patient's active speech level (RMS, in int16 units): -20 dBFS, a clear voice at arm's length
SPEECH_LEVEL = 32768 * 0.1


@dataclass(frozen=True)
class Condition:
    """A room: noise kind and SNR, or an effect on the speech."""

    noise: str = ""  # "", "white", "babble"
    snr_db: float = 0.0
    effect: str = ""  # "", "reverb", "telephone", "quiet", "leading_silence"
    #: the reverberant room's RT60 (s)
    rt60: float = 0.7
    #: steady noise: utterances must never reach the cut-off here
    steady: bool = False


CONDITIONS = {
    "clean": Condition(),
    "white_20": Condition("white", 20, steady=True),
    "white_10": Condition("white", 10, steady=True),
    "white_5": Condition("white", 5, steady=True),
    "babble_20": Condition("babble", 20),
    "babble_10": Condition("babble", 10),
    "babble_5": Condition("babble", 5),
    "reverb": Condition(effect="reverb"),
    # a tiled day room and a corridor: reverberation of 1 s and more (issue 33)
    "reverb_1s": Condition(effect="reverb", rt60=1.0),
    "reverb_1.5s": Condition(effect="reverb", rt60=1.5),
    # people talking nearby, about as loud as the patient (issue 33: 5-10 dB)
    "talk_7": Condition("babble", 7),
    "telephone": Condition(effect="telephone"),
    "quiet_-20dB": Condition(effect="quiet"),
    "leading_silence": Condition(effect="leading_silence"),
}
QUICK_CONDITIONS = ["clean", "white_10", "babble_10", "reverb"]
#: issue 33's rooms: quiet, steady noise (20 dB), reverberant (RT60 1 s and 1.5 s), talk nearby
HARD_CONDITIONS = ["clean", "white_20", "reverb_1s", "reverb_1.5s", "talk_7", "babble_5"]

#: answers in a patient's own words (item, text, option)
NATURAL_EN = [
    ("transfers", "I need a lot of help", 2),
    ("transfers", "I need a little help", 3),
    ("transfers", "I can do it by myself", 4),
    ("feeding", "I need some help", 2),
    ("feeding", "I eat by myself", 3),
    ("mobility", "I use a wheelchair", 2),
    ("mobility", "I walk with help", 3),
    ("stairs", "I need help", 2),
    ("bladder", "never", 3),
    ("bowels", "sometimes", 2),
    ("dressing", "I can't", 1),
    ("toilet", "I need some help", 2),
    ("grooming", "I need help", 1),
    ("bathing", "by myself", 2),
]
#: things patients say that are not answers (every question); "<cough>" is a cough
NON_ANSWERS_EN = [
    "um",
    "uh",
    "what?",
    "sorry?",
    "<cough>",
    "is it time for lunch yet",
    "all the time",
    "I don't know",
    "the weather is nice today",
    "where is my coat",
    "hello",
    "my daughter is coming later",
    "banana split",
    "can you say that again slowly",
]
COMMANDS_EN = [
    ("call the doctor", Command.CALL_DOCTOR),
    ("repeat", Command.REPEAT),
    ("stop", Command.PAUSE),
    ("louder", Command.VOLUME_UP),
]
YES_EN = ["yes", "yes that's right", "yes it is", "that's right"]
NO_EN = ["no", "no that's wrong", "no it isn't", "no"]
NUMBER_WORDS = ["one", "two", "three", "four"]
ORDINAL_WORDS = ["first", "second", "third", "fourth"]


def patient_cases(questionnaire) -> list[tuple[str, str, object]]:
    """(item id, text, expected option / Command / None) for every question."""
    cases = []
    for item in questionnaire.items:
        for option in item.options:
            cases.append((item.id, spoken_label(option.label_in("en")), option.number))
            cases += [(item.id, s, option.number) for s in option.synonyms_in("en")]
            n = option.number - 1
            cases += [
                (item.id, NUMBER_WORDS[n], option.number),
                (item.id, f"number {NUMBER_WORDS[n]}", option.number),
                (item.id, f"the {ORDINAL_WORDS[n]} one", option.number),
            ]
        cases += [(item.id, text, None) for text in NON_ANSWERS_EN]
        cases += [(item.id, text, command) for text, command in COMMANDS_EN]
    cases += [(item, text, option) for item, text, option in NATURAL_EN]
    return list(dict.fromkeys(cases))


#: patients' voices in the kiosk's other languages (espeak-ng voice+variant, words per minute):
#: different variants, speeds and so pitches; none is the kiosk's own voice at its own rate
OTHER_VOICES = {
    "es": [("es+m3", 130), ("es-419+f2", 165), ("es+klatt", 145), ("es-419+croak", 120)],
    "fr": [("fr+m3", 135), ("fr-be+f2", 160), ("fr+klatt", 145), ("fr+croak", 120)],
    "de": [("de+m3", 130), ("de+f2", 165), ("de+klatt", 145), ("de+croak", 120)],
}
#: non-answers in the other languages ("<cough>" is a cough)
OTHER_NON_ANSWERS = {
    "es": ["eh", "¿qué?", "<cough>", "no lo sé", "¿ya es la hora de comer?", "mi hija viene luego"],
    "fr": ["euh", "quoi ?", "<cough>", "je ne sais pas", "c'est l'heure du déjeuner ?", "ma fille vient plus tard"],
    "de": ["äh", "was?", "<cough>", "ich weiß nicht", "ist es zeit zum mittagessen", "meine tochter kommt später"],
}


def language_cases(questionnaire, language: str) -> list[tuple[str, str, object]]:
    """:func:`patient_cases` in another language: each option's label and synonyms, its number
    said two ways, non-answers, and the commands repeat and call the doctor, from the kiosk's own
    words file for that language."""
    from kiosk.speech.matching import CARDINALS, COMMAND_PHRASES, NUMBER_FORMS

    cases = []
    forms = [f for f in NUMBER_FORMS[language] if "{n}" in f][:2]
    for item in questionnaire.items:
        for option in item.options:
            cases.append((item.id, spoken_label(option.label_in(language)), option.number))
            cases += [(item.id, s, option.number) for s in option.synonyms_in(language)]
            cases += [(item.id, f.format(n=CARDINALS[language][option.number - 1][0]), option.number) for f in forms]
        cases += [(item.id, text, None) for text in OTHER_NON_ANSWERS[language]]
        cases += [(item.id, COMMAND_PHRASES[language][c][0], c) for c in (Command.REPEAT, Command.CALL_DOCTOR)]
    return list(dict.fromkeys(cases))


def yes_no(language: str) -> tuple[list[str], list[str]]:
    """The replies a patient gives to "Is that right?" in ``language`` (four ways each)."""
    if language == "en":
        return YES_EN, NO_EN
    from kiosk.speech.matching import YES_NO

    yes, no = YES_NO[language]
    return [yes[i % len(yes)] for i in (0, 2, 3, 0)], [no[i % len(no)] for i in (0, 1, 2, 0)]
