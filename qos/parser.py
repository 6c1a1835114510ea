"""Parse RoQME model text into a checked :class:`~qos.model.Model`.

The grammar is a lark LALR grammar. Patterns and value expressions share one precedence ladder
(lowest first): ``->``, ``or``, ``and``, ``once``, postfix ``while(…)``/``repeat(n)``, ``|``, ``&``,
comparisons, ``+ -``, ``* /``, unary ``! -``. A checking pass then tells patterns from values, so
``update(!X)`` is fine but ``!update(X)`` is an error. Every error message starts with
``FILE:LINE:COLUMN:`` and says what was expected or what is not supported.
"""

from __future__ import annotations

import re
from pathlib import Path

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from qos.errors import ModelError
from qos.files import BadFile, read_text
from qos.model import (
    BOOLEAN, EVENTTYPE, INTENSITY_LR, NUMBER, AllOf, AnyOf, Binary, Changed, Context, EnumType, Expr,
    FollowedBy, Literal, Model, Observation, Once, Pattern, Property, Repeat, Unary, Updated, ValueType,
    Var, While, type_name,
)

GRAMMAR = r"""
start: MODEL NAME decl*

?decl: type_decl | property_decl | context_decl | observation_decl

type_decl: TYPE NAME ":" enum_type
enum_type: ENUM "{" NAME ("," NAME)* "}"

property_decl: PROPERTY NAME prop_option*
prop_option: REFERENCE NUMBER   -> reference
           | SURVIVAL TIME      -> survival

context_decl: CONTEXT NAME ":" context_type
context_type: BOOLEAN_KW | NUMBER_KW | EVENTTYPE_KW | enum_type | NAME

observation_decl: OBSERVATION NAME ":" pattern (REINFORCES | UNDERMINES) NAME [NAME]

?pattern: alternative
        | pattern "->" alternative           -> followed_by
?alternative: conjunction
            | alternative OR conjunction     -> p_or
?conjunction: once
            | conjunction AND once           -> p_and
?once: postfix
     | ONCE once                             -> once
?postfix: disjunction
        | postfix WHILE "(" pattern ")"      -> while_
        | postfix REPEAT "(" NUMBER ")"      -> repeat
?disjunction: conjunct
            | disjunction BAR conjunct       -> binary
?conjunct: comparison
         | conjunct AMP comparison           -> binary
?comparison: sum
           | sum COMPARE sum                 -> binary
?sum: product
    | sum ADD product                        -> binary
?product: unary
        | product MUL unary                  -> binary
?unary: atom
      | "!" unary                            -> not_
      | ADD unary                            -> negate
?atom: NAME                                  -> var
     | NAME "::" NAME                        -> enum_literal
     | NUMBER                                -> number
     | TRUE                                  -> true
     | FALSE                                 -> false
     | UPDATE "(" pattern ")"                -> update
     | EVENTWHEN "(" pattern ")"             -> event_when
     | NAME "(" [argument ("," argument)*] ")" -> call
     | "(" pattern ")"
?argument: pattern | TIME

MODEL: "roqme"
TYPE: "type"
ENUM: "enum"
PROPERTY: "property"
REFERENCE: "reference"
SURVIVAL: "survival"
CONTEXT: "context"
OBSERVATION: "observation"
BOOLEAN_KW: "boolean"
NUMBER_KW: "number"
EVENTTYPE_KW: "eventtype"
REINFORCES: "reinforces"
UNDERMINES: "undermines"
OR: "or"
AND: "and"
ONCE: "once"
WHILE: "while"
REPEAT: "repeat"
UPDATE: "update"
EVENTWHEN: "eventWhen"
TRUE: "true"
FALSE: "false"
COMPARE: "!=" | "<=" | ">=" | "=" | "<" | ">"
ADD: "+" | "-"
MUL: "*" | "/"
BAR: "|"
AMP: "&"
TIME.2: /[0-9]+(\.[0-9]+)?[ \t]*(ms|sec|s|min|h)(?![A-Za-z0-9_])/
NAME: /[A-Za-z_][A-Za-z0-9_]*/
NUMBER: /[0-9]+(\.[0-9]+)?/

COMMENT: /\/\/[^\n]*/ | /\/\*(.|\n)*?\*\//
%import common.WS
%ignore WS
%ignore COMMENT
"""

# The basic lexer keeps keywords reserved everywhere, so a misplaced 'reinforces' is reported as such
# instead of being read as a context name.
_PARSER = Lark(GRAMMAR, parser="lalr", lexer="basic", propagate_positions=True)

#: seconds per time unit
TIME_UNITS = {"ms": 0.001, "s": 1.0, "sec": 1.0, "min": 60.0, "h": 3600.0}

#: words of the full RoQME language this engine does not implement, with what they are
UNSUPPORTED_WORDS = {
    "timer": "timer declarations are not supported",
    "import": "imports are not supported",
    "var": "variable declarations are not supported",
    "param": "parameters are not supported",
    "every": "the 'every' pattern operator is not supported (observations re-arm after every match anyway)",
    "not": "the 'not' pattern operator is not supported",
    "within": "time-window guards ('within') are not supported",
    "where": "'where' guards are not supported",
}
AGGREGATES = {"avg", "mean", "sum", "count", "min", "max", "stdev", "median", "first", "last", "timer"}

#: how an expected terminal is described in a message
_TERMINAL_TEXT = {
    "NAME": "a name", "NUMBER": "a number", "TIME": "a time such as 100min, 30 sec or 2h",
    "COLON": "':'", "LBRACE": "'{'", "RBRACE": "'}'", "COMMA": "','", "LPAR": "'('", "RPAR": "')'",
    "REINFORCES": "'reinforces'", "UNDERMINES": "'undermines'", "COMPARE": "a comparison", "ADD": "'+' or '-'",
    "MUL": "'*' or '/'", "BAR": "'|'", "AMP": "'&'", "ENUM": "'enum'", "MODEL": "'roqme'",
}
#: what a NAME means right after a keyword
_NAME_AFTER = {
    "roqme": "a model name", "property": "a property name", "context": "a context name",
    "type": "a type name", "observation": "an observation name", "reinforces": "a property name",
    "undermines": "a property name", "::": "an enum literal", "{": "an enum literal",
}
_DECLARATION_START = {"TYPE", "PROPERTY", "CONTEXT", "OBSERVATION"}


def _describe_expected(expected: set[str], previous: str | None) -> str:
    if expected and expected <= _DECLARATION_START | {"$END"}:
        return "a declaration (type, property, context or observation)"
    if "NAME" in expected and previous in _NAME_AFTER:
        return _NAME_AFTER[previous]
    if "REINFORCES" in expected:
        return "an operator, or 'reinforces' or 'undermines' and a property"
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
            pattern = _PARSER.get_terminal(name).pattern
            text = repr(pattern.value) if pattern.type == "str" else name.lower()
        texts.append(text)
    return " or ".join(texts[:6]) or "the end of the file"


class _Source:
    """The text of a model and the name used for it in messages."""

    def __init__(self, text: str, filename: str):
        self.text = text
        self.filename = filename

    def error(self, line: int, column: int, message: str) -> ModelError:
        return ModelError(f"{self.filename}:{line}:{column}: {message}")

    def at(self, node, message: str) -> ModelError:
        if isinstance(node, Token):
            return self.error(node.line, node.column, message)
        return self.error(node.meta.line, node.meta.column, message)

    def syntax_error(self, exc: UnexpectedInput, previous: Token | None) -> ModelError:
        if isinstance(exc, UnexpectedCharacters):
            char = self.text[exc.pos_in_stream]
            return self.error(exc.line, exc.column, f"unexpected character {char!r}")
        assert isinstance(exc, UnexpectedToken)
        token = exc.token
        if token.type != "$END" and self.text.startswith("/*", token.start_pos):
            return self.at(token, "unterminated comment: '/*' without '*/'")
        for word_token in (token, previous):
            if word_token is not None and word_token.type == "NAME" and str(word_token) in UNSUPPORTED_WORDS:
                return self.at(word_token, UNSUPPORTED_WORDS[str(word_token)])
        after = f" after {str(previous)!r}" if previous is not None else ""
        expected = _describe_expected(set(exc.expected), str(previous) if previous is not None else None)
        if token.type == "$END":
            lines = self.text.splitlines() or [""]
            return self.error(len(lines), len(lines[-1]) + 1, f"expected {expected}{after}, found the end of the file")
        return self.at(token, f"expected {expected}{after}, found {str(token)!r}")


def parse_model(text: str, filename: str = "<string>") -> Model:
    """Parse and check a model; raise :class:`ModelError` naming file, line and column."""
    source = _Source(text, filename)
    parser = _PARSER.parse_interactive(text)
    # fed token by token so that an error can say what it came after
    previous = current = None
    try:
        for token in parser.iter_parse():
            previous, current = current, token
        previous = current
        tree = parser.feed_eof(current)
    except UnexpectedInput as exc:
        raise source.syntax_error(exc, previous) from None
    return _Checker(source).model(tree)


def load_model_file(path: str | Path) -> Model:
    """Read and parse a ``.roqme`` file; errors name the file by its base name."""
    path = Path(path)
    try:
        text = read_text(path)
    except BadFile as exc:
        raise ModelError(str(exc)) from None
    return parse_model(text, path.name)


class _Checker:
    """Turns the parse tree into a model, checking names and types on the way."""

    def __init__(self, source: _Source):
        self.source = source
        self.types: dict[str, EnumType] = {}
        self.properties: dict[str, Property] = {}
        self.contexts: dict[str, Context] = {}
        self.observations: dict[str, Observation] = {}
        #: every declared name -> what it is (names share one namespace)
        self.declared: dict[str, str] = {}

    def error(self, node, message: str) -> ModelError:
        return self.source.at(node, message)

    def model(self, tree: Tree) -> Model:
        _, name, *declarations = tree.children
        for declaration in declarations:
            getattr(self, declaration.data)(declaration)
        if not self.properties:
            raise self.source.error(name.line, name.column, f"model {name} declares no property")
        return Model(str(name), self.source.filename, self.properties, self.types, self.contexts,
                     self.observations)

    def _declare(self, name: Token, what: str) -> None:
        if str(name) in self.declared:
            what = self.declared[str(name)]
            article = "an" if what[0] in "aeiou" else "a"
            raise self.error(name, f"{name} is already declared as {article} {what}")
        self.declared[str(name)] = what

    def _enum(self, name: Token, tree: Tree) -> EnumType:
        literals: list[str] = []
        for literal in tree.children[1:]:
            if str(literal) in literals:
                raise self.error(literal, f"enum literal {literal} appears twice in {name}")
            literals.append(str(literal))
        return EnumType(str(name), tuple(literals))

    def type_decl(self, tree: Tree) -> None:
        _, name, enum_tree = tree.children
        self._declare(name, "type")
        self.types[str(name)] = self._enum(name, enum_tree)

    def property_decl(self, tree: Tree) -> None:
        _, name, *options = tree.children
        self._declare(name, "property")
        reference, survival, seen = 0.5, None, set()
        for option in options:
            keyword = option.children[0]
            if option.data in seen:
                raise self.error(keyword, f"{keyword} is given twice for property {name}")
            seen.add(option.data)
            if option.data == "reference":
                reference = float(option.children[1])
                if not 0.0 <= reference <= 1.0:
                    raise self.error(option.children[1], f"reference {option.children[1]} of property {name} "
                                                         "is outside [0, 1]")
            else:
                survival = self._seconds(option.children[1])
                if survival <= 0:
                    raise self.error(option.children[1], f"survival of property {name} must be positive")
        self.properties[str(name)] = Property(str(name), reference, survival)

    def _seconds(self, time: Token) -> float:
        number, unit = re.fullmatch(r"([0-9.]+)\s*([a-z]+)", str(time)).groups()
        return float(number) * TIME_UNITS[unit]

    def context_decl(self, tree: Tree) -> None:
        _, name, type_tree = tree.children
        self._declare(name, "context")
        (spec,) = type_tree.children
        if isinstance(spec, Tree):
            value_type: ValueType = self._enum(name, spec)
        elif spec.type == "NAME":
            if str(spec) not in self.types:
                raise self.error(spec, f"unknown type {spec} (declare it with 'type {spec} : enum {{…}}' "
                                       "before this context)")
            value_type = self.types[str(spec)]
        else:
            value_type = str(spec)
        self.contexts[str(name)] = Context(str(name), value_type)

    def observation_decl(self, tree: Tree) -> None:
        _, name, pattern_tree, effect, property_name, intensity = tree.children
        self._declare(name, "observation")
        pattern = self.pattern(pattern_tree)
        if str(property_name) not in self.properties:
            raise self.error(property_name, f"observation {name} {effect} unknown property {property_name}")
        level = "default"
        if intensity is not None:
            level = str(intensity).lower().replace("_", "")
            if level not in INTENSITY_LR or level == "default":
                raise self.error(intensity, f"expected an intensity (verylow, low, high, veryhigh) after "
                                            f"{str(property_name)!r}, found {str(intensity)!r}")
        self.observations[str(name)] = Observation(str(name), pattern, str(property_name),
                                                   str(effect) == "reinforces", level, name.line)

    # ---- patterns -------------------------------------------------------------------------------

    _PATTERN_NODES = {"followed_by", "p_or", "p_and", "once", "while_", "repeat", "update", "event_when"}

    def _is_pattern(self, node) -> bool:
        return isinstance(node, Tree) and node.data in self._PATTERN_NODES

    def pattern(self, node) -> Pattern:
        """A pattern; a value expression standing as a pattern becomes an occurrence."""
        if not self._is_pattern(node):
            if isinstance(node, Tree) and node.data == "var":
                context = self._context(node.children[0])
                return Updated(context.name, when_true=context.type == BOOLEAN)
            expr = self.expr(node)
            if expr.type != BOOLEAN:
                raise self.error(node, f"a {type_name(expr.type)} value cannot stand as a pattern: use "
                                       "update(…) or compare it")
            return Changed(expr, when_true=True)
        kind = node.data
        if kind == "followed_by":
            return FollowedBy(self.pattern(node.children[0]), self.pattern(node.children[1]))
        if kind == "p_or":
            return AnyOf(self.pattern(node.children[0]), self.pattern(node.children[2]))
        if kind == "p_and":
            return AllOf(self.pattern(node.children[0]), self.pattern(node.children[2]))
        if kind == "once":
            return Once(self.pattern(node.children[1]))
        if kind == "while_":
            condition = self.expr(node.children[2], role="the while condition")
            if condition.type != BOOLEAN:
                raise self.error(node.children[2], f"the while condition must be boolean, not "
                                                   f"{type_name(condition.type)}")
            return While(self.pattern(node.children[0]), condition)
        if kind == "repeat":
            count = node.children[2]
            if "." in count or int(count) < 1:
                raise self.error(count, f"repeat needs a whole number of times ≥ 1, not {count}")
            return Repeat(self.pattern(node.children[0]), int(count))
        # update(…) / eventWhen(…)
        keyword, argument = node.children
        when_true = kind == "event_when"
        if isinstance(argument, Tree) and argument.data == "var":
            context = self._context(argument.children[0])
            if when_true and context.type != BOOLEAN:
                raise self.error(argument, f"eventWhen needs a boolean, but {context.name} is "
                                           f"{type_name(context.type)}")
            return Updated(context.name, when_true=when_true)
        expr = self.expr(argument, role=f"the argument of {keyword}")
        if when_true and expr.type != BOOLEAN:
            raise self.error(argument, f"eventWhen needs a boolean expression, not {type_name(expr.type)}")
        return Changed(expr, when_true=when_true)

    def _context(self, name: Token) -> Context:
        if str(name) not in self.contexts:
            what = self.declared.get(str(name))
            detail = f" ({name} is a {what})" if what else ""
            raise self.error(name, f"unknown context {name}{detail}")
        return self.contexts[str(name)]

    # ---- value expressions ----------------------------------------------------------------------

    def expr(self, node, role: str = "a value") -> Expr:
        if self._is_pattern(node):
            operator = {"followed_by": "->", "p_or": "or", "p_and": "and", "once": "once",
                        "while_": "while", "repeat": "repeat", "update": "update", "event_when": "eventWhen"}
            raise self.error(node, f"the pattern operator '{operator[node.data]}' cannot be used in {role}; "
                                   "only values and & | ! comparisons and arithmetic can")
        kind = node.data
        if kind == "var":
            context = self._context(node.children[0])
            if context.type == EVENTTYPE:
                raise self.error(node, f"{context.name} is an eventtype and has no value: use it as a "
                                       "pattern or in update()")
            return Var(context.name, context.type)
        if kind == "number":
            return Literal(float(node.children[0]), NUMBER)
        if kind in ("true", "false"):
            return Literal(kind == "true", BOOLEAN)
        if kind == "enum_literal":
            type_token, literal = node.children
            enum = self.types.get(str(type_token))
            if enum is None and str(type_token) in self.contexts:
                enum = self.contexts[str(type_token)].type
            if not isinstance(enum, EnumType):
                raise self.error(type_token, f"{type_token} is not an enum type")
            if str(literal) not in enum.literals:
                raise self.error(literal, f"{type_token} has no literal {literal} (expected one of "
                                          f"{', '.join(enum.literals)})")
            return Literal(str(literal), enum)
        if kind == "call":
            function = str(node.children[0])
            if function in AGGREGATES:
                raise self.error(node, f"the aggregate function {function}(…) is not supported")
            raise self.error(node, f"the function {function}(…) is not supported (patterns may use "
                                   "update(…) and eventWhen(…))")
        if kind == "not_":
            operand = self.expr(node.children[0], role)
            self._expect(node.children[0], operand, BOOLEAN, "'!'")
            return Unary("!", operand, BOOLEAN)
        if kind == "negate":
            operand = self.expr(node.children[1], role)
            self._expect(node.children[1], operand, NUMBER, f"'{node.children[0]}'")
            return Unary("-", operand, NUMBER) if str(node.children[0]) == "-" else operand
        if kind == "binary":
            left_node, op_token, right_node = node.children
            op = str(op_token)
            left, right = self.expr(left_node, role), self.expr(right_node, role)
            if op in ("&", "|"):
                self._expect(left_node, left, BOOLEAN, f"'{op}'")
                self._expect(right_node, right, BOOLEAN, f"'{op}'")
                return Binary(op, left, right, BOOLEAN)
            if op in ("=", "!="):
                if left.type != right.type:
                    raise self.error(node, f"'{op}' compares {type_name(left.type)} with {type_name(right.type)}")
                return Binary(op, left, right, BOOLEAN)
            self._expect(left_node, left, NUMBER, f"'{op}'")
            self._expect(right_node, right, NUMBER, f"'{op}'")
            return Binary(op, left, right, BOOLEAN if op in ("<", "<=", ">", ">=") else NUMBER)
        raise self.error(node, f"unexpected {kind}")  # pragma: no cover - the grammar has no other node

    def _expect(self, node, expr: Expr, wanted: str, operator: str) -> None:
        if expr.type != wanted:
            raise self.error(node, f"{operator} needs a {wanted} operand, not {type_name(expr.type)}")

