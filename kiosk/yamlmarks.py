"""YAML with positions: parse a document and remember where every value was written.

Hand-edited files (questionnaires, scripted patients, the config) must report problems as
``file:line:col``. PyYAML's ``compose`` keeps the marks that ``safe_load`` throws away; this module
keeps both the constructed data and a map from each path (keys and list indexes) to its mark, and
notices duplicate keys, which ``safe_load`` silently lets the last one win.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import yaml


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a file, at a 1-based line and column."""

    file: str
    line: int
    column: int
    message: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}: {self.message}"


class Positions:
    """Maps a path inside a YAML document (keys and indexes) to where it was written."""

    def __init__(self, root: yaml.Node) -> None:
        self._marks: dict[tuple[Any, ...], tuple[int, int]] = {}
        self._key_marks: dict[tuple[Any, ...], tuple[int, int]] = {}
        #: (path of the mapping, key, position of the second occurrence)
        self.duplicate_keys: list[tuple[tuple[Any, ...], str, tuple[int, int]]] = []
        self._walk(root, ())

    @staticmethod
    def _mark(node: yaml.Node) -> tuple[int, int]:
        return node.start_mark.line + 1, node.start_mark.column + 1

    def _walk(self, node: yaml.Node, path: tuple[Any, ...]) -> None:
        self._marks[path] = self._mark(node)
        if isinstance(node, yaml.MappingNode):
            seen: set[str] = set()
            for key_node, value_node in node.value:
                key = key_node.value
                if key in seen:
                    self.duplicate_keys.append((path, key, self._mark(key_node)))
                seen.add(key)
                self._key_marks[path + (key,)] = self._mark(key_node)
                self._walk(value_node, path + (key,))
        elif isinstance(node, yaml.SequenceNode):
            for index, child in enumerate(node.value):
                self._walk(child, path + (index,))

    def of(self, path: tuple[Any, ...], *, key: bool = False) -> tuple[int, int]:
        """Position of the value at ``path`` (or of its key), falling back to the nearest parent."""
        if key and path in self._key_marks:
            return self._key_marks[path]
        while path not in self._marks and path:
            path = path[:-1]
        return self._marks.get(path, (1, 1))


def describe(path: tuple[Any, ...]) -> str:
    """A path as people read it: ``items[2].options[0].points``."""
    return "".join(f"[{p}]" if isinstance(p, int) else (f".{p}" if i else str(p)) for i, p in enumerate(path))


def parse(text: str, filename: str) -> tuple[Any, Positions | None, list[Problem]]:
    """Parse one YAML document: (data, positions, problems).

    A syntax error or an empty document gives (None, None, [that problem]); duplicate keys are
    returned as problems alongside the data.
    """
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None, None, [Problem(filename, 1, 1, "the file is empty")]
        data = loader.construct_document(node)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        return None, None, [Problem(filename, line, col, f"YAML syntax: {exc.problem or exc.context}")]
    except yaml.YAMLError as exc:
        return None, None, [Problem(filename, 1, 1, f"YAML syntax: {exc}")]
    finally:
        loader.dispose()
    positions = Positions(node)
    problems = [
        Problem(filename, line, col, f"duplicate key {key!r}" + (f" in {describe(path)}" if path else ""))
        for path, key, (line, col) in positions.duplicate_keys
    ]
    return data, positions, problems


def schema_problems(data: Any, schema: dict[str, Any], positions: Positions,
                    add: Callable[..., None]) -> None:
    """Check ``data`` against a JSON Schema, reporting each error through ``add(path, message, key=)``.

    Messages are rewritten for people: unknown keys and missing keys by name, multiples of 5 as such.
    """
    import jsonschema

    validator = jsonschema.Draft202012Validator(schema)
    for error in sorted(validator.iter_errors(data), key=lambda e: list(map(str, e.absolute_path))):
        path = tuple(error.absolute_path)
        where = describe(path) or "the file"
        if error.validator == "additionalProperties":
            for name in sorted(set(error.instance) - set(error.schema.get("properties", {}))):
                add(path + (name,), f"unknown key {name!r}" + (f" in {describe(path)}" if path else ""), key=True)
        elif error.validator == "required":
            missing = error.message.split("'")[1] if "'" in error.message else error.message
            add(path, f"{where} is missing {missing!r}")
        elif error.validator == "multipleOf":
            add(path, f"{where}: must be a multiple of {error.validator_value}, got {error.instance!r}")
        else:
            add(path, f"{where}: {error.message}")
