"""Parsed models kept between starts (``<user cache dir>/kiosk/qos-models``, 0700, files 0600).

Parsing a model needs lark and its tables and a checking pass: most of what a kiosk's start spends
on QoS. A model that parsed is kept, keyed by its text, where it was read from, Python's version
and this package's source; it is read back only while every model it imports still reads the same
(:func:`fileio.cache.kept`). A model with an error is parsed, and its error raised, every time.
"""

from __future__ import annotations

import sys
from pathlib import Path

from fileio.cache import code_digest, digest, keep, kept
from qos.errors import ModelError
from qos.model import Model

#: the cache folder's name under <user cache dir>/kiosk
KIND = "qos-models"


def parse_model_kept(text: str, filename: str = "<string>", folder: str | Path | None = None) -> Model:
    """:func:`qos.parser.parse_model`'s model, read back when it was kept; raises ModelError as it."""
    where = str(Path(folder).resolve()) if folder is not None else ""
    key = digest(KIND, text, filename, where, sys.version, code_digest(Path(__file__).parent))
    found = kept(KIND, key)
    if isinstance(found, Model):
        return found
    from qos.parser import parse_model

    model = parse_model(text, filename, folder)
    keep(KIND, key, model, [Path(imported) for imported in model.imports])
    return model


def load_model_file_kept(path: str | Path) -> Model:
    """:func:`qos.parser.load_model_file`'s model, read back when it was kept."""
    from fileio.bounded import BadFile, read_text

    path = Path(path)
    try:
        text = read_text(path)  # the project's bounded reader, as qos.source.read_model
    except BadFile as exc:
        raise ModelError(str(exc)) from None
    return parse_model_kept(text, path.name, path.parent)
