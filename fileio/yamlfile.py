"""YAML read under limits (nesting, aliases, numbers, characters, size), with its marks, and
:func:`load_data` for a file that is YAML or JSON.

Apart from :mod:`fileio.bounded` so that importing the bounded reader does not import PyYAML
(about 0.012 s): a kiosk whose words and questionnaire are kept reads no YAML at start.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import yaml
import yaml.reader
from yaml.composer import Composer

from fileio.bounded import (
    MAX_BYTES,
    MAX_DEPTH,
    MAX_DIGITS,
    MAX_NODES,
    MAX_YAML_BYTES,
    BadFile,
    Problem,
    _position,
    bad_character,
    load_json,
    read_text,
)


class _BoundedComposer(Composer):
    """PyYAML's safe loader, composing under limits: nesting depth, values after alias expansion,
    digits of an integer, and no NaN or infinity (no file of the project has a use for them).
    Mixed into a loader below, which brings the parser."""

    def __init__(self, text: str, name: str) -> None:
        # the loader is a class chosen at run time; its __init__ sets up this mixin's reader and parser
        self._loader().__init__(self, text)  # type: ignore[misc]  # __init__ called on purpose, on self
        Composer.__init__(self)
        self.name = name
        self._depth = 0
        #: node -> (values it expands to, levels it nests), for aliases to count what they repeat
        self._sizes: dict[int, tuple[int, int]] = {}

    @classmethod
    def _loader(cls) -> type:
        return cls.__bases__[1]

    def fail(self, mark: yaml.Mark | None, message: str) -> BadFile:
        line, column = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        return BadFile(Problem(self.name, line, column, message))

    def compose_node(self, parent: yaml.Node | None, index: Any) -> yaml.Node:
        event = self.peek_event()
        if self._depth >= MAX_DEPTH:
            raise self.fail(event.start_mark, f"nested more than {MAX_DEPTH} levels deep")
        self._depth += 1
        try:
            node = super().compose_node(parent, index)
        finally:
            self._depth -= 1
        if isinstance(event, yaml.AliasEvent):
            if id(node) not in self._sizes:
                raise self.fail(event.start_mark, f"the alias *{event.anchor} refers to a value that contains it")
            size, height = self._sizes[id(node)]
        elif isinstance(node, yaml.ScalarNode):
            self._check_number(node)
            if (problem := bad_character(node.value)) is not None:
                raise self.fail(node.start_mark, f"the text {problem}")
            size, height = 1, 0
        else:
            children = [
                self._sizes[id(child)]
                for pair in node.value
                for child in (pair if isinstance(node, yaml.MappingNode) else (pair,))
            ]
            size = 1 + sum(s for s, _ in children)
            height = 1 + max((h for _, h in children), default=0)
            if isinstance(node, yaml.MappingNode):
                self._check_keys(node)
        if size > MAX_NODES:
            raise self.fail(event.start_mark, f"aliases expand the file to more than {MAX_NODES:,} values")
        if self._depth + height > MAX_DEPTH:
            raise self.fail(event.start_mark, f"nested more than {MAX_DEPTH} levels deep (through an alias)")
        self._sizes[id(node)] = (size, height)
        return node

    def _check_number(self, node: yaml.ScalarNode) -> None:
        if node.tag == "tag:yaml.org,2002:int":  # decimal, 0x hex, 0o octal or 1:30 sexagesimal
            if len(node.value) > 2 * MAX_DIGITS or abs(self.construct_yaml_int(node)) >= 10**MAX_DIGITS:
                raise self.fail(
                    node.start_mark, f"the number {node.value[:20]}… is too large (more than {MAX_DIGITS} digits)"
                )
        elif node.tag == "tag:yaml.org,2002:float":
            value = self.construct_yaml_float(node)
            if not math.isfinite(value):
                raise self.fail(node.start_mark, f"{node.value!r} is not a finite number")

    def _check_keys(self, node: yaml.MappingNode) -> None:
        seen: set[str] = set()
        for key, _ in node.value:
            if isinstance(key, yaml.ScalarNode) and key.tag != "tag:yaml.org,2002:merge":
                if key.value in seen:
                    raise self.fail(key.start_mark, f"duplicate key {key.value!r}")
                seen.add(key.value)


class _SyntaxProblem(BadFile):
    """A YAML syntax error (as opposed to a limit the composer enforces)."""


class _PlainComposer(_BoundedComposer, yaml.SafeLoader):
    """On PyYAML's own parser, whose syntax errors say what it found where."""


#: on libyaml's parser when PyYAML has it: a few times faster (a file near the size cap in well
#: under a second); the composing, where the limits are, stays in Python
_FastComposer = (
    type("_FastComposer", (_BoundedComposer, yaml.CSafeLoader), {}) if yaml.__with_libyaml__ else _PlainComposer
)


def compose_yaml(text: str, name: str) -> yaml.Node | None:
    """The node tree of one YAML document (None when empty), with its marks; :class:`BadFile` for a
    syntax error, duplicate keys, nesting deeper than :data:`MAX_DEPTH`, aliases expanding past
    :data:`MAX_NODES` values, integers of more than :data:`MAX_DIGITS` digits, NaN or infinity, or
    a text holding a lone surrogate or control character (:func:`bad_character`), escaped or not."""
    if len(text) > MAX_YAML_BYTES:
        raise BadFile(
            Problem(name, 1, 1, f"the file is larger than {MAX_YAML_BYTES // 1024} KB of YAML; is it the right file?")
        )
    try:
        return _compose(_FastComposer, text, name)
    except _SyntaxProblem:
        if _FastComposer is _PlainComposer:
            raise
        # libyaml's syntax messages are terse ("did not find expected node content"); PyYAML's
        # own parser says what it found instead, at the cost of its speed on this bad file only
        return _compose(_PlainComposer, text, name)


def _compose(kind: type[_BoundedComposer], text: str, name: str) -> yaml.Node | None:
    try:
        composer = kind(text, name)  # PyYAML's reader refuses control characters here
    except yaml.reader.ReaderError as exc:
        raise _SyntaxProblem(
            Problem(name, *_position(text, exc.position), f"character #x{exc.character:04x} is not allowed in YAML")
        ) from None
    try:
        return composer.get_single_node()
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, column = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise _SyntaxProblem(Problem(name, line, column, f"YAML syntax: {exc.problem or exc.context}")) from None
    except yaml.reader.ReaderError as exc:  # met while reading on
        raise _SyntaxProblem(
            Problem(name, *_position(text, exc.position), f"character #x{exc.character:04x} is not allowed in YAML")
        ) from None
    except yaml.YAMLError as exc:
        raise _SyntaxProblem(Problem(name, 1, 1, f"YAML syntax: {str(exc).splitlines()[0]}")) from None
    finally:
        composer.dispose()


def construct_yaml(node: yaml.Node, name: str) -> Any:
    """The Python value of a node from :func:`compose_yaml` (safe types only); :class:`BadFile`
    for what the safe constructor refuses, such as a ``!!python`` tag or a list used as a key."""
    constructor = yaml.SafeLoader("")
    try:
        return constructor.construct_document(node)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, column = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise BadFile(Problem(name, line, column, f"YAML: {exc.problem or exc.context}")) from None
    finally:
        constructor.dispose()


def load_yaml(text: str, name: str) -> Any:
    """One YAML document's value, read under :func:`compose_yaml`'s limits (None when empty)."""
    node = compose_yaml(text, name)
    return None if node is None else construct_yaml(node, name)


def load_data(path: str | Path) -> Any:
    """A ``.json`` file's value, or a YAML file's (any other name), read under every limit above."""
    text = read_text(path, MAX_BYTES if str(path).endswith(".json") else MAX_YAML_BYTES)
    return load_json(text, str(path)) if str(path).endswith(".json") else load_yaml(text, str(path))
