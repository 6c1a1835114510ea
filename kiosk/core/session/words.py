"""The words of the prompts the session builds itself (not from the questionnaire's items): Yes and
No when it asks back, and the languages to start in on the welcome. Each option is a label
shown on its button and the synonyms a patient may say for it, in the prompt's language; the voice
channel builds its grammar from them, like from a question's options.

Synonyms never use the voice commands' words ("continue", "stop", "repeat", ... in
``kiosk.speech.matching``): a phrase meaning two things is no answer at all.
"""

from __future__ import annotations

from collections.abc import Mapping

#: option number → (label, synonyms), per language, for "Is that right?"
CONFIRM_WORDS: Mapping[str, Mapping[int, tuple[str, tuple[str, ...]]]] = {
    "en": {
        1: ("Yes", ("yes", "yeah", "yes please", "yes that's right", "that's right", "right", "correct")),
        2: ("No", ("no", "nope", "no that's wrong", "that's wrong", "wrong", "not right", "incorrect")),
    },
    "es": {
        1: ("Sí", ("sí", "sí señor", "sí es correcto", "es correcto", "correcto", "eso es", "así es")),
        2: ("No", ("no", "no es correcto", "incorrecto", "está mal", "eso no")),
    },
    "fr": {
        1: ("Oui", ("oui", "oui c'est ça", "c'est ça", "c'est juste", "exact", "exactement", "correct")),
        2: ("Non", ("non", "non c'est faux", "c'est faux", "faux", "pas ça", "ce n'est pas ça")),
    },
}

#: each language's name as the patient would say it, in each prompt language
LANGUAGE_NAMES: Mapping[str, Mapping[str, tuple[str, ...]]] = {
    "en": {"en": ("English",), "es": ("Spanish",), "fr": ("French",)},
    "es": {"en": ("inglés",), "es": ("español", "castellano"), "fr": ("francés",)},
    "fr": {"en": ("anglais",), "es": ("espagnol",), "fr": ("français",)},
}

#: each language's own name: the label of its start option on the welcome
OWN_NAME: Mapping[str, str] = {"en": "English", "es": "Español", "fr": "Français"}

#: the explanation's one option (any answer key, the remote's numbers and touching Start also start)
START_LABEL: Mapping[str, str] = {"en": "Start", "es": "Empezar", "fr": "Commencer"}

#: what a patient says to start, in each language
START_WORDS: Mapping[str, tuple[str, ...]] = {
    "en": ("start", "begin", "let's start", "start please", "ready", "I'm ready"),
    "es": ("empezar", "empiece", "empecemos", "comenzar", "comience", "listo", "lista", "estoy listo", "estoy lista"),
    "fr": ("commencer", "commencez", "commençons", "démarrer", "je suis prêt", "je suis prête", "prêt", "prête"),
}
