"""The project's files: written owner-only, read bounded.

Traces, exports and plots can name a patient, so nobody else may read them (:func:`open_private`).
Every file a user hands the kiosk or the engine is read through :func:`read_text` and
:func:`load_json` or :func:`fileio.yamlfile.load_yaml`, which refuse what would crash or hang a loader
(YAML in a module of its own: PyYAML is not imported by a start that reads no YAML).
"""

from __future__ import annotations

import json
import math
import os
import re
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

from basis import record
from basis.errors import KioskError


@contextmanager
def open_private(path: str | Path, binary: bool = False) -> Iterator[IO]:
    """Create or replace ``path`` for writing, readable by its owner only (mode 0600).

    ``os.open``'s mode applies only to a file it creates, so an existing file (say 0644) is
    tightened with ``fchmod`` before anything is written into it. Raises ``OSError``.
    """
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    try:
        os.fchmod(descriptor, 0o600)
    except OSError:
        os.close(descriptor)
        raise
    if binary:
        with os.fdopen(descriptor, "wb") as handle:
            yield handle
    else:
        with os.fdopen(descriptor, "w", encoding="utf-8") as handle:
            yield handle


def write_private(path: str | Path, data: str | bytes) -> None:
    """Write text (UTF-8) or bytes to ``path``, created or replaced with mode 0600. Raises ``OSError``."""
    with open_private(path, binary=isinstance(data, bytes)) as handle:
        handle.write(data)


def write_error(path: str | Path, exc: OSError) -> str:
    """The one-line message for a file that cannot be written: ``cannot write PATH: reason``."""
    return f"cannot write {path}: {exc.strerror or exc}"


# ---------------------------------------------------------------------------------------------
# Reading the project's hand-edited and recorded files, bounded.
#
# Every loader (questionnaire, configuration, adaptation policy, remote profiles, scripted
# patients, context traces, RoQME models) reads through here, so a file that is too big, not
# UTF-8, binary, nested without end, an alias bomb, or full of NaN and thousand-digit numbers is
# one `file:line:col: problem` before any loader sees it, in bounded time and memory.

#: the largest file read (bytes): a JSON trace of a long session stays far below it
MAX_BYTES = 4 * 1024 * 1024
#: the largest YAML file: PyYAML composes a few hundred KB a second, and a bad file must be
#: refused within one (the biggest real one, the questionnaire, is 22 KB)
MAX_YAML_BYTES = 128 * 1024
#: how deeply mappings and lists may nest (the deepest real file nests 6 levels)
MAX_DEPTH = 40
#: values a YAML document may hold once aliases are expanded (a "billion laughs" file holds 10⁹)
MAX_NODES = 200_000
#: digits an integer may have: larger ones are no count, time or threshold, and cost quadratic time
MAX_DIGITS = 15


@record
class Problem:
    """One thing wrong with a file, at a 1-based line and column."""

    file: str
    line: int
    column: int
    message: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}: {self.message}"


class BadFile(KioskError, ValueError):
    """A file cannot be read as the text, YAML or JSON it should be; ``problem`` says where and what."""

    def __init__(self, problem: Problem) -> None:
        super().__init__(str(problem))
        self.problem = problem


def _position(data: bytes | str, offset: int) -> tuple[int, int]:
    if isinstance(data, bytes):
        return data.count(b"\n", 0, offset) + 1, offset - (data.rfind(b"\n", 0, offset) + 1) + 1
    return data.count("\n", 0, offset) + 1, offset - (data.rfind("\n", 0, offset) + 1) + 1


def read_text(path: str | Path, limit: int = MAX_BYTES) -> str:
    """A UTF-8 text file's contents (a leading byte-order mark dropped); :class:`BadFile` when it
    cannot be read, is not a regular file (a device, a FIFO), is larger than ``limit`` bytes, holds
    a NUL byte or is not UTF-8. Reads at most ``limit + 1`` bytes."""
    name = str(path)
    try:
        # O_NONBLOCK: a FIFO named by mistake must not wait for a writer; it is refused just below
        descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
        with os.fdopen(descriptor, "rb") as handle:
            if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):
                raise BadFile(Problem(name, 1, 1, "not a regular file"))
            data = handle.read(limit + 1)
    except OSError as exc:
        raise BadFile(Problem(name, 1, 1, f"cannot read the file: {exc.strerror or exc}")) from None
    if len(data) > limit:
        raise BadFile(Problem(name, 1, 1, f"the file is larger than {limit // 1024} KB; is it the right file?"))
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise BadFile(Problem(name, 1, 1, "the file is UTF-16 text; save it as UTF-8"))
    if (nul := data.find(b"\0")) >= 0:
        raise BadFile(Problem(name, *_position(data, nul), "a NUL byte: this is not a text file"))
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        raise BadFile(
            Problem(
                name,
                *_position(data, exc.start),
                f"not UTF-8 text (byte 0x{data[exc.start]:02x}); save the file as UTF-8",
            )
        ) from None


#: characters no text of the project may hold, even written as an escape ("\\ud800", "\\x00",
#: "\\e"): lone surrogates (not characters: they cannot be encoded, printed or stored), control
#: characters other than tab and line breaks, and the two non-characters; the same set YAML refuses
#: when written raw
_BAD_CHARACTER = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x84\x86-\x9f\ud800-\udfff\ufffe\uffff]")


def bad_character(text: str) -> str | None:
    """What is wrong with ``text`` if it holds a character no file may (see :data:`_BAD_CHARACTER`),
    as the end of a sentence naming the character; None when it holds none."""
    found = _BAD_CHARACTER.search(text)
    if found is None:
        return None
    code = ord(found.group())
    kind = (
        "a lone surrogate, not a character"
        if 0xD800 <= code <= 0xDFFF
        else "a non-character"
        if code >= 0xFFFE
        else "a control character"
    )
    return f"holds U+{code:04X}, {kind}; remove it"


def _finite(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"{text} is not a finite number")
    return value


def _bounded_int(text: str) -> int:
    if len(text.lstrip("-")) > MAX_DIGITS:
        raise ValueError(f"the number {text[:20]}… is too large (more than {MAX_DIGITS} digits)")
    return int(text)


def _refuse_constant(text: str) -> None:
    raise ValueError(f"{text} is not a finite number")


_JSON_TOKENS = re.compile(r'"(?:[^"\\]|\\.)*"|[\[\]{}]|-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?|NaN|-?Infinity')
_COLON = re.compile(r"\s*:")


def _scan_json(text: str, name: str) -> None:
    """One pass over the tokens, so that nesting, duplicate keys and bad numbers are reported with
    their position before :func:`json.loads` builds anything (it reports none of them)."""
    objects: list[set[str] | None] = []  # per open bracket: the keys of an object, None for a list
    for token in _JSON_TOKENS.finditer(text):
        kind = token.group()

        def fail(message: str, at: int = token.start()) -> BadFile:
            return BadFile(Problem(name, *_position(text, at), message))

        if kind in ("[", "{"):
            if len(objects) >= MAX_DEPTH:
                raise fail(f"nested more than {MAX_DEPTH} levels deep")
            objects.append(set() if kind == "{" else None)
        elif kind in ("]", "}"):
            if objects:
                objects.pop()
        elif kind.startswith('"'):
            if "\\" in kind and (problem := bad_character(_json_string(kind))) is not None:
                raise fail(f"the text {problem}")
            keys = objects[-1] if objects else None
            if keys is not None and _COLON.match(text, token.end()):
                if kind in keys:
                    raise fail(f"duplicate key {json.loads(kind)!r}")
                keys.add(kind)
        else:
            try:
                _finite(kind) if kind[-1].isalpha() or "." in kind or "e" in kind.lower() else _bounded_int(kind)
            except ValueError as exc:
                raise fail(str(exc)) from None


def _json_string(token: str) -> str:
    """A JSON string token's text ('' for a malformed one: json.loads reports it, with its place)."""
    try:
        return json.loads(token)
    except ValueError:
        return ""


def load_json(text: str, name: str) -> Any:
    """A JSON document's value; :class:`BadFile` for a syntax error, duplicate keys, nesting deeper
    than :data:`MAX_DEPTH`, integers of more than :data:`MAX_DIGITS` digits, NaN or infinity, or an
    escape of a lone surrogate or control character (:func:`bad_character`)."""
    _scan_json(text, name)
    try:
        return json.loads(text, parse_float=_finite, parse_int=_bounded_int, parse_constant=_refuse_constant)
    except json.JSONDecodeError as exc:
        raise BadFile(Problem(name, exc.lineno, exc.colno, f"JSON syntax: {exc.msg}")) from None
    except (ValueError, RecursionError) as exc:  # the scan reports these first; a last guard
        raise BadFile(Problem(name, 1, 1, str(exc))) from None
