"""YAML with positions: parse a document and remember where every value was written.

Hand-edited files (questionnaires, scripted patients, the config) must report problems as
``file:line:col``. PyYAML's ``compose`` keeps the marks that ``safe_load`` throws away; this module
keeps both the constructed data and a map from each path (keys and list indexes) to its mark. The
file itself is read by ``fileio.bounded`` and ``fileio.yamlfile`` (size, encoding, nesting, aliases,
duplicate keys, numbers), the one bounded reader every loader of the project shares; PyYAML is
imported when a document is first parsed.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fileio import cache
from fileio.bounded import MAX_YAML_BYTES, BadFile, Problem, read_text

if TYPE_CHECKING:
    import yaml

__all__ = ["Positions", "Problem", "describe", "parse", "parse_file", "schema_problems"]


class Positions:
    """Maps a path inside a YAML document (keys and indexes) to where it was written."""

    def __init__(self, root: yaml.Node) -> None:
        self._marks: dict[tuple[Any, ...], tuple[int, int]] = {}
        self._key_marks: dict[tuple[Any, ...], tuple[int, int]] = {}
        self._walk(root, ())

    @staticmethod
    def _mark(node: yaml.Node) -> tuple[int, int]:
        return node.start_mark.line + 1, node.start_mark.column + 1

    def _walk(self, node: yaml.Node, path: tuple[Any, ...]) -> None:
        import yaml  # imported with the composer that made the node; PyYAML loads only when YAML is read

        self._marks[path] = self._mark(node)
        if isinstance(node, yaml.MappingNode):
            for key_node, value_node in node.value:
                key = key_node.value
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


def parse(
    text: str, filename: str, *, keep: bool | Callable[[Any], bool] = False
) -> tuple[Any, Positions | None, list[Problem]]:
    """Parse one YAML document under the shared reader's limits (``fileio.bounded``): (data, positions,
    problems).

    A document that cannot be read (syntax, duplicate keys, nesting, alias bombs, huge or
    non-finite numbers) or is empty gives (None, None, [that problem]).

    With ``keep`` (True, or a test of the data: a file holding a secret is never copied into the
    cache), a document that parsed is kept (:func:`fileio.cache.keep`, keyed by its text, this
    package's code and the Python) and read back without PyYAML, whose import and composing cost a
    kiosk's start about 0.015 s for its configuration, profile and policy files; one with a problem
    is parsed, and reported, every time.
    """
    key = cache.digest(PARSED, sys.version, _code(), text) if keep else ""
    found = cache.kept(PARSED, key) if key else None
    if isinstance(found, tuple) and len(found) == 2 and isinstance(found[1], Positions):
        return found[0], found[1], []
    from fileio.yamlfile import compose_yaml, construct_yaml

    try:
        node = compose_yaml(text, filename)
        if node is None:
            return None, None, [Problem(filename, 1, 1, "the file is empty")]
        data = construct_yaml(node, filename)
    except BadFile as exc:
        return None, None, [exc.problem]
    positions = Positions(node)
    if key and (keep is True or (callable(keep) and keep(data))):
        cache.keep(PARSED, key, (data, positions))
    return data, positions, []


#: the cache folder's name under <user cache dir>/kiosk for parsed documents (:func:`parse`)
PARSED = "parsed-yaml"


@functools.cache
def _code() -> str:
    """The digest of this package's code: a document parsed by other code is parsed again."""
    return cache.code_digest(Path(__file__).parent)


def parse_file(
    path: str | Path, name: str | None = None, *, keep: bool | Callable[[Any], bool] = False
) -> tuple[Any, Positions | None, list[Problem]]:
    """Read a YAML file through the shared bounded reader and :func:`parse` it (``keep``: as there);
    an unreadable file (missing, too big, not UTF-8, binary) is one problem. ``name`` is how
    messages call the file."""
    name = str(path) if name is None else name
    try:
        text = read_text(path, MAX_YAML_BYTES)
    except BadFile as exc:
        return None, None, [Problem(name, exc.problem.line, exc.problem.column, exc.problem.message)]
    return parse(text, name, keep=keep)


def schema_problems(data: Any, schema: dict[str, Any], positions: Positions, add: Callable[..., None]) -> None:
    """Check ``data`` against a JSON Schema, reporting each error through ``add(path, message, key=)``.

    Messages are rewritten for people: unknown keys and missing keys by name, multiples of 5 as such.
    A document that passed the same schema before, under the same jsonschema, is not checked again
    (:mod:`fileio.cache`): importing jsonschema alone costs a kiosk's start a third of Textual's.
    """
    key = _schema_key(data, schema)
    if key is not None and cache.passed("json-schema", key):
        return
    import jsonschema

    validator = jsonschema.Draft202012Validator(schema)
    errors = sorted(validator.iter_errors(data), key=lambda e: list(map(str, e.absolute_path)))
    if key is not None and not errors:
        cache.remember("json-schema", key)
    for error in errors:
        path = tuple(error.absolute_path)
        where = describe(path) or "the file"
        if error.validator == "additionalProperties":
            for name in sorted(set(error.instance) - set(error.schema.get("properties", {}))):
                add(path + (name,), f"unknown key {name!r}" + (f" in {describe(path)}" if path else ""), key=True)
        elif error.validator == "required":
            missing = error.message.split("'")[1] if "'" in error.message else error.message
            add(path, f"{where} is missing {missing!r}")
        elif error.validator == "minItems" and error.validator_value == 1 and error.instance == []:
            add(path, f"{where} is empty: list at least one")
        elif error.validator in ("minItems", "maxItems") and isinstance(error.instance, list):
            bound = "at least" if error.validator == "minItems" else "at most"
            add(path, f"{where} has {len(error.instance)}: {bound} {error.validator_value} are allowed")
        elif error.validator == "multipleOf":
            add(path, f"{where}: must be a multiple of {error.validator_value}, got {error.instance!r}")
        elif error.validator == "type" and (not path or len(repr(error.instance)) > MAX_ECHO):
            # never echo a whole file (kiosk validate /etc/passwd) or a long value back
            wanted = "a mapping of keys (key: value lines)" if error.validator_value == "object" else None
            add(
                path,
                f"{where} must be {wanted or f'of type {error.validator_value!r}'}, not {_kind_of(error.instance)}",
            )
        else:
            shown = repr(error.instance)
            message = (
                error.message if len(shown) <= MAX_ECHO else error.message.replace(shown, _kind_of(error.instance))
            )
            add(path, f"{where}: {message}")


#: the longest value a problem repeats back as written
MAX_ECHO = 60


def _kind_of(value: Any) -> str:
    """What a value is, without its content: "a text of 1,234 characters", "a list of 3 values"."""
    if isinstance(value, str):
        return f"a text of {len(value):,} characters"
    if isinstance(value, (list, dict)):
        return f"a {'list' if isinstance(value, list) else 'mapping'} of {len(value):,} values"
    return f"a {type(value).__name__}"


def _schema_key(data: Any, schema: dict[str, Any]) -> str | None:
    """What a schema check's result depends on: the document, the schema and the installed
    jsonschema (its file, found without importing it); None when that cannot be told."""
    from importlib.util import find_spec

    spec = find_spec("jsonschema")
    if spec is None or spec.origin is None:
        return None
    try:
        installed = os.stat(spec.origin)
    except OSError:
        return None
    return cache.digest(repr(schema), repr(data), spec.origin, f"{installed.st_size}:{installed.st_mtime_ns}")
