"""The RoQME grammar (lark, LALR) and the one-line messages for syntax errors.

It follows RoQME's own Xtext grammar (``RoQME.xtext`` of roqme/robmosys-roqme-itp), written anew:
declarations and ``import``s in any order after an optional ``roqme NAME`` header (RoQME wants the
imports first); terms with RoQME's
precedence, loosest first: ``once``, postfix ``while(…)``/``repeat(n)``/``range(a, b)``, ``->``, ``or``,
``and``/``not``, ``? :``, ``|``, ``&``/``!``, comparisons, ``+ -``, ``* /``. Two tolerances keep older
models working where RoQME would reject them: an operator may follow a postfix (``X while(c) or Y``
is ``(X while(c)) or Y``) and ``->`` takes an ``or`` on its right (``a -> b or c``).

Function names (``avg``, ``count``, ``at``…) and strengths are plain names, so a context may be
called ``count``; every structural word below is reserved. ``/** … */`` is a description: ignored by
the grammar, collected by :func:`descriptions_of` and attached to the declaration it precedes.
"""

from __future__ import annotations

import fcntl
import functools
import os
import sys
from contextvars import ContextVar
from pathlib import Path
from typing import Any, cast

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

GRAMMAR = r"""
start: header? (import_ | decl)*
header: MODEL ename
import_: IMPORT (ename | MODEL_FILE)
?ename: NAME | STRING

?decl: type_decl | context_decl | var_decl | param_decl | timer_decl | beliefvar_decl | property_decl
     | observation_decl

type_decl: TYPE ename ":" data_type
data_type: BOOLEAN_KW [cardinality]                               -> boolean_type
         | EVENTTYPE_KW [cardinality]                             -> eventtype_type
         | ENUM [cardinality] "{" NAME ("," NAME)* "}"            -> enum_type
         | NUMBER_KW [cardinality] bound* [UNIT ename bound*]     -> number_type
         | TIME_KW [cardinality]                                  -> time_type
cardinality: "[" NUMBER "]"
bound: (LOWER | UPPER) signed
signed: [ADD] NUMBER
?declaration: data_type | NAME

context_decl: CONTEXT NAME ":" declaration [DEFINE term]
var_decl: VAR NAME ":" declaration DEFINE term
param_decl: PARAM NAME ":" declaration [DEFAULT term]
timer_decl: TIMER NAME timer_part+
timer_part: OFFSET TIME       -> offset
          | ONETIME           -> onetime
          | PAUSED            -> paused
          | DEFINE term       -> definition
beliefvar_decl: BELIEFVAR NAME prop_option*
property_decl: PROPERTY NAME [":" declaration DEFINE term] prop_option*
prop_option: REFERENCE NUMBER   -> reference
           | SURVIVAL TIME      -> survival

observation_decl: OBSERVATION NAME ":" term (action | "{" (action [";"])+ "}")
action: (REINFORCES | UNDERMINES) NAME evidence_option*    -> evidence
      | SETS NAME DEFINE term                               -> sets
      | CLEARS NAME                                         -> clears
      | (STARTS | STOPS | RESUMES) NAME                     -> timer_action
evidence_option: NAME           -> strength
               | SURVIVAL TIME  -> evidence_survival

?term: ONCE body                             -> once
     | body
?body: seq | tail
?tail: post
     | tail OR and_p                         -> p_or
     | tail ARROW or_p                       -> followed_by
?post: body WHILE "(" term ")"               -> while_
     | body REPEAT "(" NUMBER ")"            -> repeat
     | body RANGE "(" NUMBER "," NUMBER ")"  -> range
?seq: or_p
    | seq ARROW or_p                         -> followed_by
?or_p: and_p
     | or_p OR and_p                         -> p_or
?and_p: not_p
      | and_p AND not_p                      -> p_and
?not_p: cond
      | NOT cond                             -> not_event
?cond: bor
     | bor "?" bor ":" cond                  -> conditional
?bor: band
    | bor BAR band                           -> binary
?band: bnot
     | band AMP bnot                         -> binary
?bnot: rel
     | "!" rel                               -> not_
?rel: sum
    | sum COMPARE sum                        -> binary
?sum: product
    | sum ADD product                        -> binary
?product: unary
        | product MUL unary                  -> binary
?unary: atom
      | ADD unary                            -> negate
?atom: NAME                                  -> var
     | NAME "::" NAME                        -> enum_literal
     | NUMBER                                -> number
     | NUMBER NAME                           -> unit_number
     | TIME                                  -> time
     | TRUE                                  -> true
     | FALSE                                 -> false
     | STRING                                -> string
     | BELIEF                                -> belief
     | "[" term ("," term)* "]"              -> array
     | UPDATE "(" term ")"                   -> update
     | EVENTWHEN "(" term ")"                -> event_when
     | NAME "(" [term ("," term)*] ")"       -> call
     | (NAME | BELIEF) "'" (NAME | UPDATE | EVENTWHEN) [arguments]  -> postfix_call
     | "(" term ")"
arguments: "(" [term ("," term)*] ")"

MODEL: "roqme"
IMPORT: "import"
TYPE: "type"
ENUM: "enum"
BOOLEAN_KW: "boolean"
NUMBER_KW: "number"
EVENTTYPE_KW: "eventtype"
TIME_KW: "time"
UNIT: "unit"
LOWER: "lower"
UPPER: "upper"
PROPERTY: "property"
BELIEFVAR: "beliefvar"
REFERENCE: "reference"
SURVIVAL: "survival"
CONTEXT: "context"
VAR: "var"
PARAM: "param"
DEFAULT: "default"
TIMER: "timer"
OFFSET: "offset"
ONETIME: "onetime"
PAUSED: "paused"
OBSERVATION: "observation"
REINFORCES: "reinforces"
UNDERMINES: "undermines"
SETS: "sets"
CLEARS: "clears"
STARTS: "starts"
STOPS: "stops"
RESUMES: "resumes"
OR: "or"
AND: "and"
NOT: "not"
ONCE: "once"
WHILE: "while"
REPEAT: "repeat"
RANGE: "range"
UPDATE: "update"
EVENTWHEN: "eventWhen"
BELIEF: "belief"
TRUE: "true"
FALSE: "false"
DEFINE: ":="
ARROW: "->"
COMPARE: "!=" | "<=" | ">=" | "=" | "<" | ">"
ADD: "+" | "-"
MUL: "*" | "/"
BAR: "|"
AMP: "&"
TIME.2: /[0-9]+(\.[0-9]+)?[ \t]*(ms|milliseconds?|sec|seconds?|s|min|minutes?|h|hours?|days?)(?![A-Za-z0-9_])/
NAME: /[A-Za-z_][A-Za-z0-9_]*/
NUMBER: /[0-9]+(\.[0-9]+)?/
STRING: /"(\\.|[^"\\\n])*"/
MODEL_FILE.2: /[A-Za-z0-9_.\/-]*\.roqme(?![A-Za-z0-9_])/

DESCRIPTION.3: /\/\*\*(?!\/)(.|\n)*?\*\//
COMMENT: /\/\/[^\n]*/ | /\/\*(.|\n)*?\*\//
%import common.WS
%ignore WS
%ignore COMMENT
%ignore DESCRIPTION
"""

#: the descriptions met while lexing the model being parsed (one list per parse, thread-safe)
_DESCRIPTIONS: ContextVar[list[Token]] = ContextVar("descriptions")


def children(tree: Tree) -> list[Any]:
    """``tree``'s children, read as the grammar shapes them: at each position the grammar fixes
    whether a child is a Token, a Tree or an absent optional (None); lark types them all as one
    union, so the checkers read them through this."""
    return tree.children


#: how the grammar is compiled (LALR tables); the basic lexer keeps keywords reserved everywhere, so
#: a misplaced 'reinforces' is reported as such instead of being read as a context name
_OPTIONS: dict[str, object] = {"parser": "lalr", "lexer": "basic", "propagate_positions": True}


def _keep_description(token: Token) -> Token:
    _DESCRIPTIONS.get().append(token)
    return token


@functools.cache
def parser() -> Lark:
    """The RoQME parser, built on first use and kept.

    Building the LALR tables takes longer than starting Textual, so they are kept between runs in
    the user's cache directory (``<user cache dir>/kiosk/qos``, 0700), keyed by the grammar, lark's
    version and Python's; a missing, stale or unreadable cache only means building them again.
    A first start (after an install or upgrade) copies the tables shipped beside this module
    (:data:`SHIPPED_TABLES`, written by :func:`write_shipped_tables`) instead of building them:
    lark checks their key as it checks its cache's, and builds them on a mismatch.
    """
    options = dict(_OPTIONS, lexer_callbacks={"DESCRIPTION": _keep_description})
    cache = _cache_file()
    if cache is None:
        return Lark(GRAMMAR, **options)
    try:
        lock = os.open(cache.with_suffix(".lock"), os.O_RDWR | os.O_CREAT, 0o600)
    except OSError:
        return Lark(GRAMMAR, **options)
    try:
        # one process at a time reads, or builds and writes, the cache: none sees half a file
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not cache.exists():
            _copy_shipped(cache)
        return Lark(GRAMMAR, cache=str(cache), **options)  # lark checks the key inside, rebuilds on a mismatch
    finally:
        os.close(lock)


#: the LALR tables as lark's cache keeps them, shipped with the code (a first start copies them)
SHIPPED_TABLES = Path(__file__).with_name("roqme-tables.lark")


def write_shipped_tables() -> Path:
    """Build the tables and write them to :data:`SHIPPED_TABLES`, headed by :func:`_tables_key`
    (after the grammar, lark or the Python changes:
    ``uv run python -c "import qos.grammar as g; g.write_shipped_tables()"``)."""
    from lark.lark import _LOAD_ALLOWED_OPTIONS

    built = Lark(GRAMMAR, **dict(_OPTIONS, lexer_callbacks={"DESCRIPTION": _keep_description}))
    with SHIPPED_TABLES.open("wb") as f:
        f.write(_tables_key().encode() + b"\n")
        built.save(f, _LOAD_ALLOWED_OPTIONS)
    return SHIPPED_TABLES


def _tables_key() -> str:
    """What the tables depend on: the grammar, how it is compiled, lark's version and Python's."""
    import hashlib

    import lark

    text = f"{GRAMMAR}{sorted(_OPTIONS.items())}{lark.__version__}{sys.version_info[:2]}"
    return hashlib.sha256(text.encode()).hexdigest()


def _copy_shipped(cache: Path) -> None:
    """Write the shipped tables to ``cache`` as lark keeps its cache (its key for that file, no
    grammar files to re-check: the key covers lark's own), when they were built for this grammar,
    lark and Python; lark builds them itself on any mismatch."""
    import hashlib
    import pickle

    try:
        with SHIPPED_TABLES.open("rb") as f:
            if f.readline().rstrip(b"\n").decode() != _tables_key():
                return
            tables = f.read()
    except (OSError, UnicodeDecodeError):
        return
    # lark's cache key (lark.Lark.__init__): the grammar, the options as given, its version, Python's
    given = {"cache": str(cache), **_OPTIONS}
    key = hashlib.sha256(
        (GRAMMAR + "".join(k + str(v) for k, v in given.items()) + _lark_version() + str(sys.version_info[:2])).encode()
    ).hexdigest()
    temporary = cache.with_name(f".{cache.name}.{os.getpid()}")
    try:
        with temporary.open("wb") as f:
            f.write(key.encode() + b"\n")
            pickle.dump({}, f)
            f.write(tables)
        os.replace(temporary, cache)
    except OSError:
        temporary.unlink(missing_ok=True)


def _lark_version() -> str:
    from lark import __version__

    return __version__


def _cache_file() -> Path | None:
    """Where the compiled tables are kept (:func:`fileio.cache.private_dir`: they are pickled, so
    only a directory of this user's own, closed to others, is trusted), or None."""
    import hashlib

    import lark

    from fileio.cache import private_dir

    key = hashlib.sha256(f"{GRAMMAR}{sorted(_OPTIONS.items())}{lark.__version__}{sys.version_info[:2]}".encode())
    folder = private_dir("qos")
    return None if folder is None else folder / f"roqme-{key.hexdigest()[:24]}.lark"


#: seconds per time unit (RoQME's words and the short forms older models use)
TIME_UNITS = {
    "ms": 0.001,
    "millisecond": 0.001,
    "milliseconds": 0.001,
    "s": 1.0,
    "sec": 1.0,
    "second": 1.0,
    "seconds": 1.0,
    "min": 60.0,
    "minute": 60.0,
    "minutes": 60.0,
    "h": 3600.0,
    "hour": 3600.0,
    "hours": 3600.0,
    "day": 86400.0,
    "days": 86400.0,
}

#: words of other event languages that RoQME does not have, with what to write instead
UNSUPPORTED_WORDS = {
    "every": "the 'every' pattern operator is not supported (observations re-arm after every match anyway)",
    "within": "time-window guards ('within') are not RoQME: use a timer or an aggregate over a time window",
    "where": "'where' guards are not RoQME: use while(…), or the third argument of an aggregate",
}

#: how an expected terminal is described in a message
_TERMINAL_TEXT = {
    "NAME": "a name",
    "NUMBER": "a number",
    "TIME": "a time such as 100min, 30 seconds or 2 hours",
    "COLON": "':'",
    "LBRACE": "'{'",
    "RBRACE": "'}'",
    "COMMA": "','",
    "LPAR": "'('",
    "RPAR": "')'",
    "REINFORCES": "'reinforces'",
    "UNDERMINES": "'undermines'",
    "COMPARE": "a comparison",
    "ADD": "'+' or '-'",
    "MUL": "'*' or '/'",
    "BAR": "'|'",
    "AMP": "'&'",
    "ENUM": "'enum'",
    "MODEL": "'roqme'",
    "STRING": "a string",
    "DEFINE": "':='",
    "ARROW": "'->'",
    "LSQB": "'['",
    "RSQB": "']'",
    "SEMICOLON": "';'",
}
#: what a NAME means right after a keyword
_NAME_AFTER = {
    "roqme": "a model name",
    "property": "a property name",
    "context": "a context name",
    "type": "a type name",
    "observation": "an observation name",
    "reinforces": "a property name",
    "undermines": "a property name",
    "::": "an enum literal",
    "{": "an enum literal",
    "var": "a variable name",
    "param": "a parameter name",
    "timer": "a timer name",
    "beliefvar": "a belief variable name",
    "sets": "a variable name",
    "clears": "a property name",
    "starts": "a timer name",
    "stops": "a timer name",
    "resumes": "a timer name",
    "'": "a function name",
    "import": "a model file name",
}
_DECLARATION_START = {"TYPE", "PROPERTY", "CONTEXT", "OBSERVATION", "VAR", "PARAM", "TIMER", "BELIEFVAR"}
_ACTION_START = {"REINFORCES", "UNDERMINES", "SETS", "CLEARS", "STARTS", "STOPS", "RESUMES"}


def describe_expected(expected: set[str], previous: str | None) -> str:
    """What the parser wanted, in words."""
    if _DECLARATION_START <= expected:
        return "a declaration (type, property, context, observation, var, param, timer or beliefvar)"
    if "NAME" in expected and previous in _NAME_AFTER:
        return _NAME_AFTER[previous]
    if "REINFORCES" in expected and "SETS" in expected:
        if "OR" in expected or "AND" in expected:
            return "an operator, or an action ('reinforces' or 'undermines' and a property, sets, clears…)"
        return "an action (reinforces, undermines, sets, clears, starts, stops, resumes)"
    if {"NAME", "NUMBER", "LPAR"} <= expected:
        return "a pattern or a value"
    if expected == {"TIME"}:
        return _TERMINAL_TEXT["TIME"]
    texts = []
    for name in sorted(expected):
        if name == "$END":
            continue
        text = _TERMINAL_TEXT.get(name)
        if text is None:
            pattern = parser().get_terminal(name).pattern
            text = repr(pattern.value) if pattern.type == "str" else name.lower()
        texts.append(text)
    return " or ".join(texts[:6]) or "the end of the file"


def syntax_error(text: str, exc: UnexpectedInput, previous: Token | None) -> tuple[int, int, str]:
    """Line, column and message of a lark error (the caller adds the file name)."""
    if isinstance(exc, UnexpectedCharacters):
        return exc.line, exc.column, f"unexpected character {text[exc.pos_in_stream or 0]!r}"
    assert isinstance(exc, UnexpectedToken)
    token = exc.token
    if token.type != "$END" and text.startswith("/*", token.start_pos):
        return token.line, token.column, "unterminated comment: '/*' without '*/'"
    for word in (token, previous):
        if word is not None and word.type == "NAME" and str(word) in UNSUPPORTED_WORDS:
            return cast(int, word.line), cast(int, word.column), UNSUPPORTED_WORDS[str(word)]  # lexed: positioned
    after = f" after {str(previous)!r}" if previous is not None else ""
    expected = describe_expected(set(exc.expected), str(previous) if previous is not None else None)
    if token.type == "$END":
        lines = text.splitlines() or [""]
        return len(lines), len(lines[-1]) + 1, f"expected {expected}{after}, found the end of the file"
    return token.line, token.column, f"expected {expected}{after}, found {str(token)!r}"


def parse_text(text: str):
    """Parse model text; returns (tree, descriptions) or raises (UnexpectedInput, previous token)."""
    descriptions: list[Token] = []
    reset = _DESCRIPTIONS.set(descriptions)
    try:
        interactive = parser().parse_interactive(text)
        # fed token by token so that an error can say what it came after
        previous = current = None
        try:
            for token in interactive.iter_parse():
                previous, current = current, token
            previous = current
            tree = interactive.feed_eof(current)
        except UnexpectedInput as exc:
            raise SyntaxProblem(*syntax_error(text, exc, previous)) from None
    finally:
        _DESCRIPTIONS.reset(reset)
    return tree, descriptions


class SyntaxProblem(Exception):
    """A syntax error at (line, column) with its message; the parser turns it into a ModelError."""

    def __init__(self, line: int, column: int, message: str):
        super().__init__(line, column, message)
        self.line, self.column, self.message = line, column, message
