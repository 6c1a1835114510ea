"""The words of the prompts the session builds itself (not from the questionnaire's items): Yes and
No when it asks back, and the languages to start in on the welcome. Each option is a label
shown on its button and the synonyms a patient may say for it, in the prompt's language; the voice
channel builds its grammar from them, like from a question's options.

The words are each language's file (``kiosk/core/words/<code>.yaml``, its ``prompts`` section), so
a language added there has its prompts here. Synonyms never use the voice commands' words
("continue", "stop", "repeat", ... in the files' ``speech.commands``): a phrase meaning two things
is no answer at all.
"""

from __future__ import annotations

from collections.abc import Mapping

from kiosk.core.words import Table

#: option number → (label, synonyms), per language, for "Is that right?"
CONFIRM_WORDS: Mapping[str, Mapping[int, tuple[str, tuple[str, ...]]]] = Table(
    lambda words: {
        1: (words.prompts["yes_label"], words.prompts["yes_words"]),
        2: (words.prompts["no_label"], words.prompts["no_words"]),
    }
)

#: each language's name as the patient would say it, in each prompt language
LANGUAGE_NAMES: Mapping[str, Mapping[str, tuple[str, ...]]] = Table(lambda words: words.prompts["language_names"])

#: each language's own name: the label of its start option on the welcome
OWN_NAME: Mapping[str, str] = Table(lambda words: words.name)

#: the explanation's one option (any answer key, the remote's numbers and touching Start also start)
START_LABEL: Mapping[str, str] = Table(lambda words: words.screen["start"])

#: what a patient says to start, in each language
START_WORDS: Mapping[str, tuple[str, ...]] = Table(lambda words: words.prompts["start_words"])

#: the rest screen between two instruments of a battery ("{title}": the next instrument's)
REST_TEXT: Mapping[str, str] = Table(lambda words: words.screen["rest"])

#: the rest screen's one option
CONTINUE_LABEL: Mapping[str, str] = Table(lambda words: words.screen["rest_continue"])

#: the wait after questions in a row went unanswered ("Are you still there? Touch the screen to go on.")
UNATTENDED_TEXT: Mapping[str, str] = Table(lambda words: words.screen["unattended"])

#: that wait's one option
GO_ON_LABEL: Mapping[str, str] = Table(lambda words: words.screen["go_on"])

#: "Shall I call the nurse?" after a call heard by voice, and the same asking for a press
CALL_CONFIRM: Mapping[str, tuple[str, str]] = Table(
    lambda words: (words.screen["call_confirm"], words.screen["call_confirm_press"])
)

#: a walk-up patient's start of an instrument their caregiver answers: who it is for, calmly
CAREGIVER_ONLY_TEXT: Mapping[str, str] = Table(lambda words: words.screen["caregiver_only"])
