"""The kiosk's formula language: a small, bounded subset of FHIRPath, parsed into a tree.

What an instrument's total may say (docs/formulas.md lists it with examples): numbers, strings,
``true``/``false``, ``{}``, ``%resource``, paths (``item``, ``linkId``, ``answer``, ``value``,
``code``...), ``where(...)``, arithmetic, comparisons, boolean logic, ``|``, and the functions of
:data:`FUNCTIONS`. Nothing reads the clock, runs a regular expression or iterates without bound,
so the same answers always give the same total in bounded time. A hand-written parser rather
than fhirpathpy's ANTLR one because every limit (length, tokens, nesting, nodes) is checked before
any recursion could overflow, and the tree is small enough to reason about (:mod:`.proof`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from decimal import Decimal
from functools import lru_cache
from typing import Any

from basis.errors import KioskError

#: the longest formula (characters): a published score fits in a few hundred
MAX_LENGTH = 2000
#: the most tokens a formula may have
MAX_TOKENS = 600
#: the most nodes its tree may have
MAX_NODES = 400
#: the deepest its tree may be (parentheses, calls and chained operators all count)
MAX_DEPTH = 100
#: the most digits a number written in a formula may have
MAX_DIGITS = 12

#: function name -> (fewest, most) arguments
FUNCTIONS: dict[str, tuple[int, int]] = {
    "iif": (2, 3),
    "where": (1, 1),
    "exists": (0, 1),
    "empty": (0, 0),
    "count": (0, 0),
    "sum": (0, 0),
    "min": (0, 0),
    "max": (0, 0),
    "first": (0, 0),
    "last": (0, 0),
    "not": (0, 0),
    "weight": (0, 0),
    "ordinal": (0, 0),
    "round": (0, 1),
    "floor": (0, 0),
    "ceiling": (0, 0),
    "truncate": (0, 0),
    "abs": (0, 0),
}

#: functions FHIRPath has that a total may not use, and why
REFUSED: dict[str, str] = {
    **dict.fromkeys(
        ("today", "now", "timeOfDay"), "reads the clock (the same answers must always give the same total)"
    ),
    **dict.fromkeys(
        ("matches", "replaceMatches", "matchesFull"),
        "runs a regular expression, which can take hours on one answer",
    ),
    **dict.fromkeys(
        ("repeat", "repeatAll", "descendants", "children", "aggregate"),
        "iterates without a bound",
    ),
    "trace": "prints to the kiosk's terminal",
    "defineVariable": "defines variables, which the kiosk's formulas do not have",
    "resolve": "fetches other resources",
}

_BINARY = {
    "implies": 1,
    "or": 2,
    "xor": 2,
    "and": 3,
    "=": 5,
    "!=": 5,
    "<": 6,
    ">": 6,
    "<=": 6,
    ">=": 6,
    "|": 7,
    "+": 8,
    "-": 8,
    "*": 9,
    "/": 9,
    "div": 9,
    "mod": 9,
}
_TOKEN = re.compile(
    r"(?P<space>\s+)|(?P<number>\d+(?:\.\d+)?)|(?P<string>'(?:[^'\\]|\\.)*')"
    r"|(?P<name>[A-Za-z_][A-Za-z0-9_]*)|(?P<env>%[A-Za-z_][A-Za-z0-9_]*)|(?P<this>\$this)"
    r"|(?P<op><=|>=|!=|[=<>+\-*/|(),.{}])"
)
_ESCAPES = {"'": "'", "\\": "\\", "/": "/", "n": "\n", "t": "\t", "r": "\r", "f": "\f", '"': '"', "`": "`"}


class FormulaError(KioskError, ValueError):
    """A formula outside the kiosk's formula language; ``at`` is its 1-based character."""

    def __init__(self, message: str, at: int) -> None:
        self.message, self.at = message, at
        super().__init__(f"at character {at}: {message}")


@dataclass(frozen=True, slots=True)
class Node:
    """One node of a formula's tree. ``kind``: number, string, boolean, empty, env, this, name
    (a path step), call (``value`` the function, ``args``), path (``args`` = base, step), binary
    (``value`` the operator), negate. ``at`` is its 1-based character in the formula."""

    kind: str
    value: Any
    args: tuple[Node, ...]
    at: int
    depth: int = 1
    size: int = 1


def node(kind: str, value: Any, args: tuple[Node, ...], at: int) -> Node:
    """A node, refused once the tree would be deeper or larger than the limits."""
    depth = 1 + max((a.depth for a in args), default=0)
    size = 1 + sum(a.size for a in args)
    if depth > MAX_DEPTH:
        raise FormulaError(f"the formula is nested more than {MAX_DEPTH} deep: split it or simplify it", at)
    if size > MAX_NODES:
        raise FormulaError(f"the formula has more than {MAX_NODES} parts: simplify it", at)
    return Node(kind, value, args, at, depth, size)


def _tokens(text: str) -> list[tuple[str, str, int]]:
    found: list[tuple[str, str, int]] = []
    at = 0
    while at < len(text):
        match = _TOKEN.match(text, at)
        if match is None:
            raise FormulaError(f"{text[at]!r} is not part of the kiosk's formula language", at + 1)
        kind = match.lastgroup or ""
        if kind != "space":
            found.append((kind, match.group(), at + 1))
            if len(found) > MAX_TOKENS:
                raise FormulaError(f"the formula has more than {MAX_TOKENS} words and signs: simplify it", at + 1)
        at = match.end()
    found.append(("end", "", len(text) + 1))
    return found


class _Parser:
    """Precedence climbing; recursion only on parentheses, arguments and unary minus, each
    counted against :data:`MAX_DEPTH` before it recurses."""

    def __init__(self, text: str) -> None:
        self.tokens = _tokens(text)
        self.i = 0
        self.nesting = 0

    def peek(self) -> tuple[str, str, int]:
        return self.tokens[self.i]

    def take(self, value: str | None = None) -> tuple[str, str, int]:
        token = self.tokens[self.i]
        if value is not None and token[1] != value:
            shown = repr(token[1]) if token[0] != "end" else "the end"
            raise FormulaError(f"expected {value!r} but found {shown}", token[2])
        self.i += 1
        return token

    def nested(self, at: int) -> None:
        self.nesting += 1
        if self.nesting > MAX_DEPTH:
            raise FormulaError(f"the formula is nested more than {MAX_DEPTH} deep: split it or simplify it", at)

    def expression(self, floor: int = 0) -> Node:
        left = self.unary()
        while True:
            kind, value, at = self.peek()
            rank = _BINARY.get(value) if kind in ("op", "name") else None
            if rank is None or rank <= floor:
                return left
            self.take()
            self.nested(at)
            right = self.expression(rank)
            self.nesting -= 1
            left = node("binary", value, (left, right), at)

    def unary(self) -> Node:
        kind, value, at = self.peek()
        if value in ("-", "+") and kind == "op":
            self.take()
            self.nested(at)
            operand = self.unary()
            self.nesting -= 1
            return node("negate", None, (operand,), at) if value == "-" else operand
        return self.postfix(self.term())

    def postfix(self, base: Node) -> Node:
        while self.peek()[1] == "." and self.peek()[0] == "op":
            self.take()
            kind, value, at = self.take()
            if kind != "name":
                raise FormulaError(f"expected a name after '.' but found {value!r}", at)
            base = node("path", None, (base, self.step(value, at)), at)
        if self.peek()[1] == "[":
            raise FormulaError("indexes ([n]) are not in the kiosk's formula language: use first()", self.peek()[2])
        return base

    def step(self, name: str, at: int) -> Node:
        if self.peek()[1] != "(":
            return node("name", name, (), at)
        if name in REFUSED:
            raise FormulaError(f"{name}() is not allowed in a total: it {REFUSED[name]}", at)
        if name not in FUNCTIONS:
            raise FormulaError(
                f"{name}() is not in the kiosk's formula language (it has {', '.join(sorted(FUNCTIONS))})", at
            )
        self.take("(")
        self.nested(at)
        args: list[Node] = []
        if self.peek()[1] != ")":
            args.append(self.expression())
            while self.peek()[1] == ",":
                self.take()
                args.append(self.expression())
        self.take(")")
        self.nesting -= 1
        low, high = FUNCTIONS[name]
        if not low <= len(args) <= high:
            wanted = str(low) if low == high else f"{low} to {high}"
            raise FormulaError(f"{name}() takes {wanted} argument{'s' if high != 1 else ''}, not {len(args)}", at)
        return node("call", name, tuple(args), at)

    def term(self) -> Node:
        kind, value, at = self.take()
        if kind == "number":
            if len(value.replace(".", "")) > MAX_DIGITS:
                raise FormulaError(f"the number {value[:20]}... has more than {MAX_DIGITS} digits", at)
            return node("number", Decimal(value) if "." in value else int(value), (), at)
        if kind == "string":
            return node("string", _unquoted(value, at), (), at)
        if kind == "env":
            if value not in ("%resource", "%context"):
                raise FormulaError(f"{value} is not known: a formula reads the answers as %resource", at)
            return node("env", value, (), at)
        if kind == "this":
            return node("this", None, (), at)
        if kind == "name":
            if value in ("true", "false"):
                return node("boolean", value == "true", (), at)
            if value in _BINARY:
                raise FormulaError(f"{value!r} needs something before it", at)
            return self.step(value, at)
        if value == "(":
            self.nested(at)
            inner = self.expression()
            self.take(")")
            self.nesting -= 1
            return inner
        if value == "{":
            self.take("}")
            return node("empty", None, (), at)
        shown = "the end of the formula" if kind == "end" else repr(value)
        raise FormulaError(f"expected a value but found {shown}", at)


def _unquoted(text: str, at: int) -> str:
    out, i = [], 1
    while i < len(text) - 1:
        char = text[i]
        if char == "\\":
            following = text[i + 1]
            if following not in _ESCAPES:
                raise FormulaError(f"'\\{following}' is not an escape the kiosk's formulas know", at + i)
            out.append(_ESCAPES[following])
            i += 2
        else:
            out.append(char)
            i += 1
    return "".join(out)


@lru_cache(maxsize=128)
def parse(text: str) -> Node:
    """The tree of a formula; :class:`FormulaError` (with its character) for anything outside the
    language or its limits. Checks the length first, so nothing long is even tokenised."""
    if len(text) > MAX_LENGTH:
        raise FormulaError(f"the formula is {len(text):,} characters long; at most {MAX_LENGTH:,} are allowed", 1)
    if not text.strip():
        raise FormulaError("the formula is empty", 1)
    parser = _Parser(text)
    tree = parser.expression()
    kind, value, at = parser.peek()
    if kind != "end":
        raise FormulaError(f"{value!r} is not part of the expression", at)
    return tree


def walk(tree: Node) -> list[Node]:
    """Every node of a tree, root first (iteratively: trees are shallow, but never trust that)."""
    found, stack = [], [tree]
    while stack:
        current = stack.pop()
        found.append(current)
        stack.extend(reversed(current.args))
    return found


def named_items(tree: Node) -> list[tuple[str, int]]:
    """(item id, character) of every string a formula compares ``linkId`` with."""
    found = []
    for part in walk(tree):
        if part.kind == "binary" and part.value in ("=", "!="):
            left, right = part.args
            for one, other in ((left, right), (right, left)):
                if other.kind == "string" and _ends_in(one, "linkId"):
                    found.append((other.value, other.at))
    return found


def _ends_in(part: Node, name: str) -> bool:
    return (part.kind == "name" and part.value == name) or (part.kind == "path" and _ends_in(part.args[1], name))
