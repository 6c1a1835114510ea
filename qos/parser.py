"""Parse RoQME model text into a checked :class:`~qos.model.Model`.

:mod:`qos.grammar` parses; this module checks declarations (names, types, bounds, actions) and
:mod:`qos.terms` checks patterns and values. Names are declared before they are used, so a model
has no cycles. Every error message starts with ``FILE:LINE:COLUMN:`` and nothing is half-loaded: a
model is returned whole or not at all.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import cast

from lark import Token, Tree

from qos.errors import ModelError
from qos.grammar import SyntaxProblem, children, parse_text
from qos.model import (
    BOOLEAN,
    EVENTTYPE,
    INTENSITY_LR,
    NUMBER,
    ArrayType,
    ClearEvidence,
    Context,
    EnumType,
    Evidence,
    Expr,
    Literal,
    Model,
    Observation,
    Pattern,
    Property,
    SetVariable,
    Timer,
    TimerAction,
    TypeSpec,
    ValueType,
    Variable,
    type_name,
)
from qos.shipped import MODELS
from qos.source import MAX_IMPORT_DEPTH, Source, check_nesting, read_model
from qos.terms import TermChecker, is_pattern, seconds_of
from qos.timers import ScheduleError, parse_schedule

_STRENGTHS = "verylow, low, medium, high, veryhigh"


def parse_model(text: str, filename: str = "<string>", folder: str | Path | None = None) -> Model:
    """Parse and check a model; raise :class:`ModelError` naming file, line and column.

    ``folder`` is where ``import`` looks for other models (default: the current directory), then
    the shipped models' folder (``import "clarc.roqme"`` from anywhere).
    """
    source = Source(text, filename, Path(folder) if folder is not None else Path("."))
    return _Checker(source).model(source)


def load_model_file(path: str | Path) -> Model:
    """Read and parse a ``.roqme`` file; errors name the file by its base name."""
    path = Path(path)
    return parse_model(read_model(path), path.name, path.parent)


def _description(token: Token) -> str:
    lines = str(token)[3:-2].strip("\n").splitlines()
    lines = [re.sub(r"^\s*\*?\s*", "", line).rstrip() for line in lines]
    return "\n".join(lines).strip()


class _Checker(TermChecker):
    """Turns parse trees into a model, checking names and types on the way."""

    def __init__(self, source: Source):
        super().__init__()
        self.source = source
        self.properties: dict[str, Property] = {}
        self.beliefvars: dict[str, Property] = {}
        self.observations: dict[str, Observation] = {}
        self.imported: list[str] = []
        #: the description (``/** … */``) of the declaration being checked
        self.description: str | None = None
        #: files being read, outermost first (an import cycle is an error)
        self.reading: list[Path] = []

    def error(self, node, message: str) -> ModelError:
        return self.source.at(node, message)

    def _tree(self, source: Source) -> tuple[Tree, list[Token]]:
        try:
            tree, descriptions = parse_text(source.text)
        except SyntaxProblem as problem:
            raise source.error(problem.line, problem.column, problem.message) from None
        check_nesting(source, tree)
        return tree, descriptions

    def model(self, source: Source) -> Model:
        if source.folder is not None and source.filename != "<string>":
            self.reading.append((source.folder / source.filename).resolve())
        tree, descriptions = self._tree(source)
        name, description = self._declarations(tree, descriptions)
        if name is None:
            name = Path(source.filename).stem if source.filename != "<string>" else "model"
        if not self.properties:
            header = children(tree)[0] if children(tree) and children(tree)[0].data == "header" else None
            line, column = (children(header)[1].line, children(header)[1].column) if header else (1, 1)
            raise source.error(line, column, f"model {name} declares no property")
        return Model(
            name,
            source.filename,
            self.properties,
            self.types,
            self.contexts,
            self.observations,
            self.beliefvars,
            self.variables,
            self.timers,
            tuple(self.streams),
            tuple(self.imported),
            description,
        )

    def _declarations(self, tree: Tree, descriptions: list[Token]) -> tuple[str | None, str | None]:
        name = model_description = None
        previous_end = 0
        for declaration in children(tree):
            start = declaration.meta.start_pos
            # the lexer's tokens carry their offsets (lark types them optional for hand-made tokens)
            mine = [d for d in descriptions if previous_end <= cast(int, d.start_pos) and cast(int, d.end_pos) <= start]
            described = _description(mine[-1]) if mine else None
            previous_end = declaration.meta.end_pos
            if declaration.data == "header":
                name, model_description = self._name(children(declaration)[1]), described
            elif declaration.data == "import_":
                self._import(declaration)
            else:
                self.description = described
                getattr(self, declaration.data)(declaration)
        return name, model_description

    def _name(self, token: Token) -> str:
        return str(token)[1:-1] if token.type == "STRING" else str(token)  # NAME or MODEL_FILE

    def _import(self, tree: Tree) -> None:
        """Merge another model's declarations into this one (names share one namespace)."""
        target = children(tree)[1]
        relative = self._name(target)
        if not relative.endswith(".roqme"):
            relative += ".roqme"
        if self.source.folder is None:
            raise self.error(target, f"cannot import {relative}: this model was not read from a file")
        path = (self.source.folder / relative).resolve()
        if not path.is_file() and "/" not in relative and (MODELS / relative).is_file():
            path = (MODELS / relative).resolve()  # the shipped models: a site's model imports "clarc.roqme"
        if path in self.reading:
            raise self.error(target, f"import cycle: {relative} imports this model back")
        if str(path) in self.imported:
            return  # already merged (imported twice by different models)
        if not path.is_file():
            raise self.error(target, f"cannot import {relative}: no such model file")
        if len(self.reading) >= MAX_IMPORT_DEPTH:
            raise self.error(target, f"imports nest more than {MAX_IMPORT_DEPTH} models deep")
        outer = self.source
        self.source = Source(read_model(path), path.name, path.parent)
        self.reading.append(path)
        try:
            imported_tree, descriptions = self._tree(self.source)
            self._declarations(imported_tree, descriptions)
        finally:
            self.reading.pop()
            self.source = outer
        self.imported.append(str(path))

    def _declare(self, name: Token, what: str) -> None:
        if str(name) in self.declared:
            what = self.declared[str(name)]
            article = "an" if what[0] in "aeiou" else "a"
            raise self.error(name, f"{name} is already declared as {article} {what}")
        self.declared[str(name)] = what

    # ---- data types -----------------------------------------------------------------------------

    def _type_spec(self, owner: str, node, what: str) -> TypeSpec:
        """The type of a declaration: a referenced type name or a data type written in place."""
        if isinstance(node, Token):
            if str(node) not in self.types:
                raise self.error(
                    node, f"unknown type {node} (declare it with 'type {node} : enum {{…}}' before this {what})"
                )
            return self.types[str(node)]
        keyword, cardinality, *rest = children(node)
        kind = node.data
        lower = upper = unit = None
        if kind == "enum_type":
            literals: list[str] = []
            for literal in rest:
                if str(literal) in literals:
                    raise self.error(literal, f"enum literal {literal} appears twice in {owner}")
                literals.append(str(literal))
            scalar: ValueType = EnumType(owner, tuple(literals))
        elif kind == "number_type":
            scalar = NUMBER
            for part in rest:
                if isinstance(part, Tree):  # a bound
                    word, signed = children(part)
                    value = float(children(signed)[1]) * (-1 if children(signed)[0] == "-" else 1)
                    lower, upper = (value, upper) if word == "lower" else (lower, value)
                elif part is not None and part.type in ("NAME", "STRING"):
                    unit = self._name(part)
            if lower is not None and upper is not None and lower > upper:
                raise self.error(node, f"the lower bound {lower:g} of {owner} is above its upper bound {upper:g}")
        elif kind == "time_type":
            scalar, unit = NUMBER, "s"
        else:
            scalar = BOOLEAN if kind == "boolean_type" else EVENTTYPE
        value_type: ValueType = scalar
        if cardinality is not None:
            size = children(cardinality)[0]
            if "." in size or int(size) < 1:
                raise self.error(size, f"an array holds a whole number ≥ 1 of values, not {size}")
            if scalar == EVENTTYPE:
                raise self.error(keyword, "an eventtype has no values to hold in an array")
            value_type = ArrayType(scalar, int(size))
        return TypeSpec(value_type, lower, upper, unit)

    def type_decl(self, tree: Tree) -> None:
        _, name_token, data_type = children(tree)
        self._declare(name_token, "type")
        name = self._name(name_token)
        self.types[name] = self._type_spec(name, data_type, "type")

    def _value_of(self, node, spec: TypeSpec, owner: str, role: str):
        """A constant of the declared type (a default, a constant definition), checked against bounds."""
        value = self.expr(node, role)
        if not isinstance(value, Literal):
            raise self.error(node, f"{role} must be a constant")
        if value.type != spec.type and not (
            isinstance(spec.type, ArrayType)
            and isinstance(value.type, ArrayType)
            and value.type.element == spec.type.element
        ):
            raise self.error(node, f"{role} is {type_name(value.type)}, but {owner} is {type_name(spec.type)}")
        if isinstance(spec.type, ArrayType) and isinstance(value.value, tuple) and len(value.value) > spec.type.size:
            raise self.error(node, f"{role} has {len(value.value)} values; {owner} holds at most {spec.type.size}")
        for number in value.value if isinstance(value.value, tuple) else (value.value,):
            problem = spec.out_of_bounds(number) if isinstance(number, float) else None
            if problem:
                raise self.error(node, f"{role}: {problem} of {owner}")
        return value.value

    # ---- contexts, variables, timers --------------------------------------------------------------

    def context_decl(self, tree: Tree) -> None:
        _, name, type_node, _define, definition = children(tree)
        self._declare(name, "context")
        spec = self._type_spec(str(name), type_node, "context")
        if definition is None:
            self.contexts[str(name)] = Context(str(name), spec.type, spec, None, self.description)
            return
        self.defining = (str(name), spec.type)
        try:
            if spec.type == EVENTTYPE:
                value: Expr | Pattern = self.pattern(definition)
            else:
                if is_pattern(definition):
                    raise self.error(
                        definition,
                        f"a pattern defines an eventtype context; {name} is "
                        f"{type_name(spec.type)}: declare it eventtype, or define it by a "
                        "value",
                    )
                value = self.expr(definition, f"the definition of {name}")
                if value.type != spec.type:
                    raise self.error(
                        definition, f"the definition of {name} is {type_name(value.type)}, not {type_name(spec.type)}"
                    )
        finally:
            self.defining = None
        context = Context(str(name), spec.type, spec, value, self.description)
        self.contexts[str(name)] = context
        self.streams.append((str(name), context))

    def var_decl(self, tree: Tree) -> None:
        _, name, type_node, _define, definition = children(tree)
        self._declare(name, "variable")
        spec = self._type_spec(str(name), type_node, "variable")
        self.defining = (str(name), spec.type)  # its own enum literals: var W : enum {C, D} := W::D
        try:
            value = self.expr(definition, f"the definition of {name}")
            if value.type != spec.type:
                raise self.error(
                    definition, f"the definition of {name} is {type_name(value.type)}, not {type_name(spec.type)}"
                )
            if isinstance(value, Literal):
                variable = Variable(
                    str(name),
                    spec.type,
                    spec,
                    self._value_of(definition, spec, str(name), "the value"),
                    None,
                    False,
                    self.description,
                )
            else:
                variable = Variable(str(name), spec.type, spec, None, value, False, self.description)
                self.streams.append((str(name), variable))
        finally:
            self.defining = None
        self.variables[str(name)] = variable

    def param_decl(self, tree: Tree) -> None:
        _, name, type_node, _default, default = children(tree)
        self._declare(name, "parameter")
        spec = self._type_spec(str(name), type_node, "parameter")
        if spec.type == EVENTTYPE:
            raise self.error(type_node, f"parameter {name} holds a value; an eventtype has none")
        self.defining = (str(name), spec.type)  # its own enum literals: default L::A
        try:
            initial = None if default is None else self._value_of(default, spec, str(name), "the default")
        finally:
            self.defining = None
        self.variables[str(name)] = Variable(str(name), spec.type, spec, initial, None, True, self.description)

    def timer_decl(self, tree: Tree) -> None:
        _, name, *parts = children(tree)
        self._declare(name, "timer")
        seen: set[str] = set()
        interval = schedule = None
        offset, onetime, paused = 0.0, False, False
        for part in parts:
            keyword = children(part)[0]
            if part.data in seen:
                raise self.error(keyword, f"{keyword} is given twice for timer {name}")
            seen.add(part.data)
            if part.data == "offset":
                offset = seconds_of(children(part)[1])
            elif part.data == "onetime":
                onetime = True
            elif part.data == "paused":
                paused = True
            else:
                interval, schedule = self._timer_definition(name, children(part)[1])
        if "definition" not in seen:
            raise self.error(
                name, f'timer {name} needs a definition: timer {name} := 1 minutes, or := schedule("0, 9, *, *, *")'
            )
        self.timers[str(name)] = Timer(str(name), interval, schedule, offset, onetime, paused, self.description)

    def _timer_definition(self, name: Token, node):
        if isinstance(node, Tree) and node.data == "time":
            interval = seconds_of(children(node)[0])
            if interval <= 0:
                raise self.error(node, f"the interval of timer {name} must be longer than 0")
            return interval, None
        if isinstance(node, Tree) and node.data == "call" and str(children(node)[0]) == "schedule":
            args = [child for child in children(node)[1:] if child is not None]
            if len(args) != 1 or not (isinstance(args[0], Tree) and args[0].data == "string"):
                raise self.error(node, 'schedule takes one string: schedule("minutes, hours, days, months, weekdays")')
            try:
                return None, parse_schedule(str(children(args[0])[0])[1:-1])
            except ScheduleError as exc:
                raise self.error(args[0], f"bad schedule: {exc}") from None
        raise self.error(node, f'timer {name} is defined by a time (1 minutes) or schedule("…")')

    # ---- properties and belief variables ---------------------------------------------------------

    def property_decl(self, tree: Tree) -> None:
        _, name, type_node, _define, transformation, *options = children(tree)
        self._declare(name, "property")
        output = None
        if transformation is not None:
            spec = self._type_spec(str(name), type_node, "property")
            self.self_belief_allowed, self.defining = True, (str(name), spec.type)
            try:
                output = self.expr(transformation, f"the output of {name}")
            finally:
                self.self_belief_allowed, self.defining = False, None
            if output.type != spec.type:
                raise self.error(
                    transformation, f"the output of {name} is {type_name(output.type)}, not {type_name(spec.type)}"
                )
        self.properties[str(name)] = self._belief(name, "property", options, output)
        self.beliefs[str(name)] = self.properties[str(name)]

    def beliefvar_decl(self, tree: Tree) -> None:
        _, name, *options = children(tree)
        self._declare(name, "belief variable")
        self.beliefvars[str(name)] = self.beliefs[str(name)] = self._belief(name, "belief variable", options, None)

    def _belief(self, name: Token, what: str, options: list, output) -> Property:
        reference, survival, seen = 0.5, None, set()
        for option in options:
            keyword = children(option)[0]
            if option.data in seen:
                raise self.error(keyword, f"{keyword} is given twice for {what} {name}")
            seen.add(option.data)
            if option.data == "reference":
                reference = float(children(option)[1])
                if not 0.0 <= reference <= 1.0:
                    raise self.error(
                        children(option)[1], f"reference {children(option)[1]} of {what} {name} is outside [0, 1]"
                    )
            else:
                survival = seconds_of(children(option)[1])
                if survival <= 0:
                    raise self.error(children(option)[1], f"survival of {what} {name} must be positive")
        return Property(str(name), reference, survival, output, self.description)

    # ---- observations ----------------------------------------------------------------------------

    def observation_decl(self, tree: Tree) -> None:
        _, name, pattern_tree, *action_trees = children(tree)
        self._declare(name, "observation")
        description = self.description
        pattern = self.pattern(pattern_tree)
        actions = tuple(getattr(self, f"_{action.data}")(name, action) for action in action_trees if action is not None)
        self.observations[str(name)] = Observation(str(name), pattern, actions, name.line, description)

    def _belief_target(self, name: Token, verb: Token, target: Token) -> str:
        if str(target) not in self.beliefs:
            what = self.declared.get(str(target))
            if what:
                raise self.error(
                    target,
                    f"observation {name} {verb} {target}, a {what}: only a property or a beliefvar holds evidence",
                )
            raise self.error(target, f"observation {name} {verb} unknown property {target}")
        return str(target)

    def _evidence(self, name: Token, tree: Tree) -> Evidence:
        verb, target, *options = children(tree)
        level, survival, seen = "default", None, set()
        previous = target
        for option in options:
            if option.data == "strength":
                word = children(option)[0]
                if str(word).lower().replace("_", "") not in INTENSITY_LR or str(word) == "default":
                    # a misspelt keyword on the next line lands here too, so say what it came after
                    raise self.error(
                        word, f"expected a strength ({_STRENGTHS}) after {str(previous)!r}, found {str(word)!r}"
                    )
            if option.data in seen:
                raise self.error(
                    option, f"observation {name} gives {option.data.replace('evidence_', '')} twice for {target}"
                )
            seen.add(option.data)
            previous = children(option)[-1]
            if option.data == "strength":
                level = str(children(option)[0]).lower().replace("_", "")
            else:
                survival = seconds_of(children(option)[1])
                if survival <= 0:
                    raise self.error(children(option)[1], "the survival of evidence must be positive")
        return Evidence(self._belief_target(name, verb, target), str(verb) == "reinforces", level, survival)

    def _sets(self, name: Token, tree: Tree) -> SetVariable:
        _, target, _define, value_node = children(tree)
        variable = self.variables.get(str(target))
        if variable is None or variable.parameter:
            what = "a parameter, a constant" if variable is not None else self.declared.get(str(target), "undeclared")
            raise self.error(target, f"observation {name} sets {target}, which is {what}: only a var can be set")
        value = self.expr(value_node, f"the value set to {target}")
        if value.type != variable.type:
            raise self.error(value_node, f"{target} is {type_name(variable.type)}, not {type_name(value.type)}")
        return SetVariable(str(target), value)

    def _clears(self, name: Token, tree: Tree) -> ClearEvidence:
        verb, target = children(tree)
        return ClearEvidence(self._belief_target(name, verb, target))

    def _timer_action(self, name: Token, tree: Tree) -> TimerAction:
        verb, target = children(tree)
        if str(target) not in self.timers:
            raise self.error(target, f"observation {name} {verb} {target}, which is not a timer")
        return TimerAction(str(verb), str(target))
