"""A questionnaire that loaded is kept between starts (``<user cache dir>/kiosk/questionnaires``,
0700, files 0600) and read back, so a kiosk's start skips composing its YAML with positions and
checking it (about a third of building the kiosk).

It is read back only while everything the load read still reads the same: the file, the bundled
instruments folder (the schema), the kiosk's words files (their languages are checked against),
and the Python of this package, the words and :mod:`fileio` (:func:`fileio.cache.kept`). A file
with a problem is loaded, and its problems raised, every time.
"""

from __future__ import annotations

import sys
from pathlib import Path

from fileio.cache import code_digest, digest, keep, kept
from kiosk.core.questionnaire.loading import bundled_path, load_questionnaire
from kiosk.core.questionnaire.model import Questionnaire
from kiosk.core.words import LANGUAGES, WORDS_DIR

#: the cache folder's name under <user cache dir>/kiosk
KIND = "questionnaires"


def load_questionnaire_kept(path: str | Path | None = None) -> Questionnaire:
    """:func:`~kiosk.core.questionnaire.load_questionnaire`'s questionnaire, read back when kept;
    raises QuestionnaireError as it does."""
    file = Path(path) if path is not None else bundled_path()
    instruments = bundled_path().parent
    read = [file, *sorted(instruments.iterdir()), *sorted(Path(WORDS_DIR).glob("*.yaml"))]
    try:
        code = [code_digest(folder) for folder in (Path(__file__).parent, Path(WORDS_DIR), _fileio_dir())]
        languages = ",".join(LANGUAGES)  # a site's words files add languages the checks accept
        key = digest(KIND, str(path), str(file.resolve()), sys.version, languages, *code, *map(str, read))
    except OSError:  # what cannot be read is the load's to report
        return load_questionnaire(path)
    found = kept(KIND, key)
    if isinstance(found, Questionnaire):
        return found
    questionnaire = load_questionnaire(path)
    keep(KIND, key, questionnaire, [f for f in read if f.is_file()])
    return questionnaire


def _fileio_dir() -> Path:
    import fileio

    return Path(fileio.__file__).parent
