"""The kiosk's formula language for instrument totals: a bounded subset of FHIRPath.

:func:`compute` is the one way a formula is evaluated (the kiosk's scoring, ``kiosk validate``,
the station's scoring of captured definitions): it refuses what is outside the language
(:mod:`.syntax`: no clock, no regular expressions, no unbounded iteration, no ``trace``; limits on
length, parts and nesting) and stops any evaluation past its budget of steps
(:mod:`.evaluation`), so no formula, however hostile, hangs or crashes what reads it.
:func:`~.proof.prove` shows, before any patient answers, that a formula gives one whole number in
its declared range for every complete set of answers. The language is described in
``docs/formulas.md``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from kiosk.core.questionnaire.formula.evaluation import ITEM_WEIGHT, MAX_STEPS, ORDINAL_VALUE, Budget, evaluate_tree
from kiosk.core.questionnaire.formula.proof import ItemAnswers, prove
from kiosk.core.questionnaire.formula.syntax import FUNCTIONS, MAX_DEPTH, MAX_LENGTH, MAX_NODES, FormulaError, parse
from kiosk.core.questionnaire.formula.values import EvaluationError

__all__ = [
    "FUNCTIONS",
    "ITEM_WEIGHT",
    "MAX_DEPTH",
    "MAX_LENGTH",
    "MAX_NODES",
    "MAX_STEPS",
    "ORDINAL_VALUE",
    "Budget",
    "EvaluationError",
    "FormulaError",
    "ItemAnswers",
    "compute",
    "prove",
]


def compute(expression: str, resource: Mapping[str, Any], budget: Budget | None = None) -> list[Any]:
    """What ``expression`` gives on ``resource`` (a QuestionnaireResponse whose chosen Codings
    carry their itemWeight): numbers as int where whole, else Decimal. :class:`EvaluationError`
    with one sentence (and the character) for a formula outside the language, one that fails on
    these answers, or one past ``budget`` (default: :data:`MAX_STEPS` steps)."""
    try:
        tree = parse(expression)
    except FormulaError as exc:
        raise EvaluationError(str(exc)) from None
    return evaluate_tree(tree, resource, budget or Budget())
