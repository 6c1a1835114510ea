"""Checking RoQME terms: the parse tree of a pattern or a value becomes a typed expression or pattern.

Patterns and values share one grammar; this pass tells them apart, so ``update(!X)`` is fine but
``!update(X)`` is an error. Stateful values (aggregates, ``period``) are lifted out of the expression
into named streams (``#1``, ``#2``…) that the engine keeps up to date; the expression reads them like a
context. Every error names the node's line and column.
"""

from __future__ import annotations

from typing import cast

from lark import Token, Tree

from qos.expressions import variables_of
from qos.grammar import TIME_UNITS, children
from qos.model import (
    BOOLEAN,
    EVENTTYPE,
    NUMBER,
    SELF_BELIEF,
    Aggregate,
    AllOf,
    AndNot,
    AnyOf,
    ArrayType,
    Binary,
    Call,
    Changed,
    Conditional,
    Context,
    EnumType,
    Expr,
    FollowedBy,
    Literal,
    Once,
    Pattern,
    Period,
    Range,
    Repeat,
    Stream,
    Unary,
    Updated,
    ValueType,
    Var,
    While,
    type_name,
)

AGGREGATES = ("avg", "min", "max", "count", "sum", "increasing", "decreasing", "stable")
ARITHMETIC = ("pow", "sqrt", "exp", "abs")
COLLECTION = ("first", "last", "at", "size", "isEmpty", "includes")
#: how many arguments each function of values takes (the array itself counts)
_ARITY = {
    "pow": 2,
    "sqrt": 1,
    "exp": 1,
    "abs": 1,
    "first": 1,
    "last": 1,
    "size": 1,
    "isEmpty": 1,
    "at": 2,
    "includes": 2,
}
_PATTERN_NODES = {
    "followed_by",
    "p_or",
    "p_and",
    "once",
    "while_",
    "repeat",
    "range",
    "update",
    "event_when",
    "not_event",
}
_OPERATOR = {
    "followed_by": "->",
    "p_or": "or",
    "p_and": "and",
    "once": "once",
    "while_": "while",
    "repeat": "repeat",
    "range": "range",
    "update": "update",
    "event_when": "eventWhen",
    "not_event": "not",
}


def seconds_of(token: Token) -> float:
    """A TIME token (``100min``, ``5 minutes``) in seconds."""
    text = str(token)
    number = text.rstrip("abcdefghijklmnopqrstuvwxyz").rstrip()
    return float(number) * TIME_UNITS[text[len(number) :].strip()]


def is_pattern(node) -> bool:
    """True for a node only a pattern can be (an event operator)."""
    return isinstance(node, Tree) and node.data in _PATTERN_NODES


class TermChecker:
    """The term half of the model checker; the declaration half (:class:`qos.parser._Checker`) holds
    the symbol tables it reads: types, contexts, variables, timers, beliefs."""

    def __init__(self):
        self.types: dict = {}
        self.contexts: dict[str, Context] = {}
        self.variables: dict = {}
        self.timers: dict = {}
        #: properties and beliefvars by name
        self.beliefs: dict = {}
        self.declared: dict[str, str] = {}
        self.streams: list[tuple[str, Stream]] = []
        #: set while checking a property's output transformation, where ``belief`` is its value
        self.self_belief_allowed = False
        #: (name, enum type) of a context whose definition is being checked (its own literals resolve)
        self.defining: tuple[str, ValueType] | None = None

    def error(self, node, message: str) -> Exception:  # pragma: no cover - defined by the checker
        raise NotImplementedError

    def _stream(self, definition: Stream, type_: ValueType) -> Var:
        name = f"#{len(self.streams) + 1}"
        self.streams.append((name, definition))
        return Var(name, type_)

    # ---- patterns -------------------------------------------------------------------------------

    def pattern(self, node) -> Pattern:
        """A pattern; a value standing as a pattern becomes an occurrence."""
        if isinstance(node, Tree) and node.data == "postfix_call" and children(node)[1].type in ("UPDATE", "EVENTWHEN"):
            subject, keyword, arguments = children(node)  # X'update is update(X), X'eventWhen is eventWhen(X)
            if arguments is not None and any(child is not None for child in children(arguments)):
                raise self.error(node, f"{subject}'{keyword} takes no arguments")
            kind = "update" if keyword.type == "UPDATE" else "event_when"
            node = Tree(kind, [keyword, Tree("var", [subject], node.meta)], node.meta)
        if not is_pattern(node):
            return self._occurrence(node)
        kind = node.data
        kids = children(node)
        if kind == "followed_by":
            return FollowedBy(self.pattern(kids[0]), self.pattern(kids[2]))
        if kind == "p_or":
            return AnyOf(self.pattern(kids[0]), self.pattern(kids[2]))
        if kind == "p_and":
            left, right = kids[0], kids[2]
            left_not = isinstance(left, Tree) and left.data == "not_event"
            right_not = isinstance(right, Tree) and right.data == "not_event"
            if left_not and right_not:
                raise self.error(node, "'not a and not b' never occurs: one side of 'and' must occur")
            if right_not:
                return AndNot(self.pattern(left), self.pattern(children(right)[1]))
            if left_not:
                return AndNot(self.pattern(right), self.pattern(children(left)[1]))
            return AllOf(self.pattern(left), self.pattern(right))
        if kind == "not_event":
            raise self.error(node, "'not p' never occurs on its own: use it beside 'and' (a and not p)")
        if kind == "once":
            return Once(self.pattern(kids[1]))
        if kind == "while_":
            condition = self.expr(kids[2], role="the while condition")
            if condition.type != BOOLEAN:
                raise self.error(kids[2], f"the while condition must be boolean, not {type_name(condition.type)}")
            return While(self.pattern(kids[0]), condition)
        if kind == "repeat":
            return Repeat(self.pattern(kids[0]), self._count(kids[2], "repeat needs a whole number of times"))
        if kind == "range":
            low = self._count(kids[2], "range needs whole numbers of times")
            high = self._count(kids[3], "range needs whole numbers of times")
            if high < low:
                raise self.error(kids[3], f"range({low}, {high}) is empty: the upper bound is below the lower")
            return Range(self.pattern(kids[0]), low, high)
        # update(…) / eventWhen(…)
        keyword, argument = kids
        when_true = kind == "event_when"
        if isinstance(argument, Tree) and argument.data == "var" and str(children(argument)[0]) in self.contexts:
            context = self.contexts[str(children(argument)[0])]
            if when_true and context.type != BOOLEAN:
                raise self.error(
                    argument, f"eventWhen needs a boolean, but {context.name} is {type_name(context.type)}"
                )
            return Updated(context.name, when_true=when_true)
        expr = self.expr(argument, role=f"the argument of {keyword}")
        if when_true and expr.type != BOOLEAN:
            raise self.error(argument, f"eventWhen needs a boolean expression, not {type_name(expr.type)}")
        return self._changed(argument, expr, when_true)

    def _changed(self, node, expr: Expr, when_true: bool) -> Changed:
        """A change of a value, which only an update of a context (or of a stream) can bring."""
        if not any(name in self.contexts or name.startswith("#") for name in variables_of(expr)):
            raise self.error(
                node,
                "this value reads no context, so it never changes by an update: use it as a "
                "condition (X while(…)) or read a context",
            )
        return Changed(expr, when_true=when_true)

    def _count(self, token: Token, message: str) -> int:
        if "." in token or int(token) < 1:
            raise self.error(token, f"{message} ≥ 1, not {token}")
        return int(token)

    def _occurrence(self, node) -> Pattern:
        if isinstance(node, Tree) and node.data == "var":
            name = str(children(node)[0])
            if name in self.timers:
                return Updated(name)
            if name in self.contexts:
                context = self.contexts[name]
                return Updated(context.name, when_true=context.type == BOOLEAN)
        if isinstance(node, Tree) and node.data == "enum_literal":
            return self._enum_occurrence(node)
        expr = self.expr(node)
        if expr.type != BOOLEAN:
            raise self.error(
                node, f"a {type_name(expr.type)} value cannot stand as a pattern: use update(…) or compare it"
            )
        return self._changed(node, expr, True)

    def _enum_occurrence(self, node: Tree) -> Pattern:
        """``ctx::LIT`` as a pattern: every update of ctx to LIT (RoQME's enum filter)."""
        literal = self.expr(node)
        qualifier = str(children(node)[0])
        if qualifier in self.contexts:
            context = self.contexts[qualifier]
        else:
            users = [c for c in self.contexts.values() if c.type == literal.type]
            if len(users) != 1:
                raise self.error(
                    node,
                    f"{qualifier}::{children(node)[1]} as a pattern needs the context it is "
                    f"about: write CONTEXT::{children(node)[1]}",
                )
            context = users[0]
        return While(Updated(context.name), Binary("=", Var(context.name, context.type), literal, BOOLEAN))

    # ---- values ---------------------------------------------------------------------------------

    def expr(self, node, role: str = "a value") -> Expr:
        """A checked value expression."""
        if is_pattern(node):
            raise self.error(
                node,
                f"the pattern operator '{_OPERATOR[node.data]}' cannot be used in {role}; "
                "only values and & | ! comparisons and arithmetic can",
            )
        kind = node.data
        kids = children(node)
        if kind == "var":
            return self._name_value(kids[0])
        if kind == "number":
            return Literal(float(kids[0]), NUMBER)
        if kind == "unit_number":  # a unit-measured value: the unit documents it
            return Literal(float(kids[0]), NUMBER)
        if kind == "time":
            return Literal(seconds_of(kids[0]), NUMBER)
        if kind in ("true", "false"):
            return Literal(kind == "true", BOOLEAN)
        if kind == "string":
            raise self.error(node, "a string is only a value in import and schedule(…)")
        if kind == "belief":
            if not self.self_belief_allowed:
                raise self.error(
                    node,
                    "'belief' is the property's own belief: use it in a property's output "
                    "transformation (property P : number := belief * 100)",
                )
            return Var(SELF_BELIEF, NUMBER)
        if kind == "enum_literal":
            return self._enum_literal(node)
        if kind == "array":
            return self._array(node)
        if kind in ("call", "postfix_call"):
            return self._call(node)
        if kind == "conditional":
            return self._conditional(node, role)
        if kind == "not_":
            operand = self.expr(kids[0], role)
            self._expect(kids[0], operand, BOOLEAN, "'!'")
            return Unary("!", operand, BOOLEAN)
        if kind == "negate":
            operand = self.expr(kids[1], role)
            self._expect(kids[1], operand, NUMBER, f"'{kids[0]}'")
            if str(kids[0]) == "+":
                return operand
            if isinstance(operand, Literal):
                return Literal(-cast(float, operand.value), NUMBER)
            return Unary("-", operand, NUMBER)
        if kind == "binary":
            return self._binary(node, role)
        raise self.error(node, f"unexpected {kind}")  # pragma: no cover - the grammar has no other node

    def _name_value(self, name: Token) -> Expr:
        text = str(name)
        if text in self.contexts:
            context = self.contexts[text]
            if context.type == EVENTTYPE:
                raise self.error(name, f"{text} is an eventtype and has no value: use it as a pattern or in update()")
            return Var(text, context.type)
        if text in self.variables:
            return Var(text, self.variables[text].type)
        if text in self.beliefs:
            return Var(text, NUMBER)
        if text in self.timers:
            raise self.error(name, f"{text} is a timer and has no value: use it as a pattern")
        if self.declared.get(text) in ("context", "variable"):
            raise self.error(name, f"{text} is used in its own definition")
        what = self.declared.get(text)
        detail = f" ({text} is a {what})" if what else ""
        raise self.error(name, f"unknown context {text}{detail}")

    def _enum_literal(self, node: Tree) -> Literal:
        type_token, literal = children(node)
        qualifier = str(type_token)
        enum = None
        if qualifier in self.types:
            enum = self.types[qualifier].type
        elif qualifier in self.contexts:
            enum = self.contexts[qualifier].type
        elif qualifier in self.variables:
            enum = self.variables[qualifier].type
        elif self.defining is not None and self.defining[0] == qualifier:
            enum = self.defining[1]
        if isinstance(enum, ArrayType):  # an array of enum literals: its elements' type
            enum = enum.element
        if not isinstance(enum, EnumType):
            raise self.error(type_token, f"{type_token} is not an enum type")
        if str(literal) not in enum.literals:
            raise self.error(
                literal, f"{type_token} has no literal {literal} (expected one of {', '.join(enum.literals)})"
            )
        return Literal(str(literal), enum)

    def _array(self, node: Tree) -> Literal:
        values = [self.expr(child) for child in children(node)]
        for child, value in zip(children(node), values):
            if not isinstance(value, Literal) or isinstance(value.type, ArrayType):
                raise self.error(child, "an array holds constants: numbers, booleans or enum literals")
            if value.type != values[0].type:
                raise self.error(
                    child, f"an array holds one type: {type_name(values[0].type)}, not {type_name(value.type)}"
                )
        return Literal(tuple(cast(Literal, value).value for value in values), ArrayType(values[0].type, len(values)))

    def _conditional(self, node: Tree, role: str) -> Conditional:
        condition_node, then_node, otherwise_node = children(node)
        condition = self.expr(condition_node, role)
        self._expect(condition_node, condition, BOOLEAN, "the condition of '? :'")
        then, otherwise = self.expr(then_node, role), self.expr(otherwise_node, role)
        if then.type != otherwise.type:
            raise self.error(
                otherwise_node,
                f"both branches of '? :' need one type: {type_name(then.type)} and {type_name(otherwise.type)}",
            )
        return Conditional(condition, then, otherwise, then.type)

    def _binary(self, node: Tree, role: str) -> Binary:
        left_node, op_token, right_node = children(node)
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

    def _expect(self, node, expr: Expr, wanted: str, operator: str) -> None:
        if expr.type != wanted:
            raise self.error(node, f"{operator} needs a {wanted} operand, not {type_name(expr.type)}")

    # ---- functions ------------------------------------------------------------------------------

    def _call(self, node: Tree) -> Expr:
        if node.data == "postfix_call":
            subject, function, arguments = children(node)
            if isinstance(subject, Token) and subject.type == "BELIEF":
                raise self.error(
                    node,
                    f"belief'{function} is not supported: a belief changes continuously, not "
                    "by updates; aggregate a context instead",
                )
            args = [Tree("var", [subject], node.meta)] + (
                [child for child in children(arguments) if child is not None] if arguments is not None else []
            )
        else:
            function, *rest = children(node)
            args = [child for child in rest if child is not None]
        name = str(function)
        if name in ("update", "eventWhen"):
            raise self.error(
                node,
                f"the pattern operator '{name}' cannot be used in a value; only values and & | ! "
                "comparisons and arithmetic can",
            )
        if name in AGGREGATES:
            return self._aggregate(node, name, args)
        if name == "period":
            return self._period(node, args)
        if name == "schedule":
            raise self.error(node, 'schedule(…) defines a timer: timer T := schedule("…")')
        if name not in _ARITY:
            raise self.error(
                node,
                f"unknown function {name}(…) (functions: {', '.join(AGGREGATES + ARITHMETIC + COLLECTION)}"
                ", period, update, eventWhen)",
            )
        if len(args) != _ARITY[name]:
            raise self.error(
                node, f"{name} takes {_ARITY[name]} argument{'s' if _ARITY[name] > 1 else ''}, not {len(args)}"
            )
        values = [self.expr(arg, f"the arguments of {name}") for arg in args]
        if name in ARITHMETIC:
            for arg, value in zip(args, values):
                self._expect(arg, value, NUMBER, name)
            return Call(name, tuple(values), NUMBER)
        array = values[0]
        if not isinstance(array.type, ArrayType):
            raise self.error(args[0], f"{name} needs an array, not {type_name(array.type)}")
        element = array.type.element
        if name == "at":
            self._expect(args[1], values[1], NUMBER, "the index of at")
        if name == "includes" and values[1].type != element:
            raise self.error(args[1], f"includes looks for a {type_name(element)}, not {type_name(values[1].type)}")
        result = {"size": NUMBER, "isEmpty": BOOLEAN, "includes": BOOLEAN}.get(name, element)
        return Call(name, tuple(values), result)

    def _aggregate(self, node: Tree, name: str, args: list) -> Var:
        if not 1 <= len(args) <= 3:
            raise self.error(
                node, f"{name} takes a context, then optionally a window (a count or a time) and a condition"
            )
        source_node = args[0]
        source_name = (
            str(children(source_node)[0]) if isinstance(source_node, Tree) and source_node.data == "var" else None
        )
        if source_name in self.contexts:
            source_type = self.contexts[source_name].type
        else:  # any other value: aggregate a hidden stream of its values
            value = self.expr(source_node, f"the argument of {name}")
            source_type = value.type
            source_name = f"#{len(self.streams) + 1}"
            self.streams.append((source_name, Context(source_name, value.type, definition=value)))
        if name != "count" and source_type != NUMBER:
            raise self.error(source_node, f"{name} needs a number to aggregate, not {type_name(source_type)}")
        window: int | float | None = None
        if len(args) > 1:
            window_node = args[1]
            kind = window_node.data if isinstance(window_node, Tree) else None
            if kind == "time":
                window = seconds_of(children(window_node)[0])
            elif kind == "number" and "." not in children(window_node)[0] and int(children(window_node)[0]) >= 1:
                window = int(children(window_node)[0])
            else:
                raise self.error(
                    window_node, f"the window of {name} is a whole number of updates (3) or a time (5 minutes)"
                )
            if isinstance(window, float) and window <= 0:
                raise self.error(window_node, f"the window of {name} must be longer than 0")
        where = None
        if len(args) > 2:
            where = self.expr(args[2], f"the condition of {name}")
            self._expect(args[2], where, BOOLEAN, f"the condition of {name}")
        result = BOOLEAN if name in ("increasing", "decreasing", "stable") else NUMBER
        return self._stream(Aggregate(name, source_name, window, where, result), result)

    def _period(self, node: Tree, args: list) -> Var:
        if len(args) != 1:
            raise self.error(node, "period takes one argument: a context, or 'a -> b'")
        (argument,) = args
        if isinstance(argument, Tree) and argument.data == "var" and str(children(argument)[0]) in self.contexts:
            return self._stream(Period(str(children(argument)[0])), NUMBER)
        if isinstance(argument, Tree) and argument.data == "followed_by":
            first, then = self.pattern(children(argument)[0]), self.pattern(children(argument)[2])
            return self._stream(Period(None, first, then), NUMBER)
        raise self.error(
            argument, "period needs a context (how long it kept its value) or 'a -> b' (the time from a to b)"
        )
