"""A model's text as the checker reads it: the name errors carry, the bounded reader, the nesting limit.

Every error names ``FILE:LINE:COLUMN``; reading goes through :mod:`fileio.bounded`, so an import
of a huge or unreadable file is one clear error, never a hang.
"""

from __future__ import annotations

from pathlib import Path
from typing import cast

from lark import Token, Tree

from fileio.bounded import BadFile, read_text
from qos.errors import ModelError
from qos.grammar import children


class Source:
    """The text of a model and the name used for it in messages."""

    def __init__(self, text: str, filename: str, folder: Path | None):
        self.text = text
        self.filename = filename
        #: where its imports are looked for
        self.folder = folder

    def error(self, line: int, column: int, message: str) -> ModelError:
        return ModelError(f"{self.filename}:{line}:{column}: {message}")

    def at(self, node, message: str) -> ModelError:
        if isinstance(node, Token):  # lark's tokens from the lexer all have a position
            return self.error(cast(int, node.line), cast(int, node.column), message)
        return self.error(node.meta.line, node.meta.column, message)


def read_model(path: Path) -> str:
    try:
        return read_text(path)  # the project's bounded reader
    except BadFile as exc:
        raise ModelError(str(exc)) from None


#: how many models deep imports may go (each level is a few nested calls)
MAX_IMPORT_DEPTH = 32
#: how deeply terms may nest (parentheses, chains of operators): checking and running a term recurse
#: once per level, and no model a person writes comes near this
MAX_NESTING = 200


def check_nesting(source: Source, tree: Tree) -> None:
    """Refuse a term nested deeper than MAX_NESTING, naming its declaration (checked without recursion)."""
    stack = [(declaration, 1, declaration) for declaration in children(tree)]
    while stack:
        node, depth, declaration = stack.pop()
        if depth > MAX_NESTING:
            raise source.at(
                declaration,
                f"{children(declaration)[1]} nests operators more than {MAX_NESTING} levels "
                "deep: split it with derived contexts",
            )
        stack.extend((child, depth + 1, declaration) for child in children(node) if isinstance(child, Tree))
