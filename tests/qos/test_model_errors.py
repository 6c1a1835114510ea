"""Malformed models: each is rejected with one message naming file, line, column and the problem."""

from __future__ import annotations

import pytest

from qos import ModelError, load_model, parse_model

#: a valid header the observation cases build on (observations start on line 7)
HEAD = (
    "roqme M\nproperty P\ncontext B : boolean\ncontext N : number\ncontext E : eventtype\ncontext S : enum {ON, OFF}\n"
)

CASES = [
    ("", "m.roqme:1:1: model m declares no property"),
    (
        "roqme M\nproperty P\nroqme N",
        "m.roqme:3:1: expected a declaration (type, property, context, observation, "
        "var, param, timer or beliefvar) after 'P', found 'roqme'",
    ),
    ("roqme", "m.roqme:1:6: expected a model name after 'roqme', found the end of the file"),
    ("roqme M\nproperty", "m.roqme:2:9: expected a property name after 'property', found the end of the file"),
    ("roqme M\nproperty P reference", "m.roqme:2:21: expected a number after 'reference', found the end of the file"),
    ("roqme M\nproperty P reference 1.5", "m.roqme:2:22: reference 1.5 of property P is outside [0, 1]"),
    (
        "roqme M\nproperty P survival 100",
        "m.roqme:2:21: expected a time such as 100min, 30 seconds or 2 hours after 'survival', found '100'",
    ),
    ("roqme M\nproperty P survival 0min", "m.roqme:2:21: survival of property P must be positive"),
    ("roqme M\nproperty P reference 0.5 reference 0.4", "m.roqme:2:26: reference is given twice for property P"),
    ("roqme M\ncontext B : boolean", "m.roqme:1:7: model M declares no property"),
    ("roqme M\nproperty P\nproperty P", "m.roqme:3:10: P is already declared as a property"),
    (
        "roqme M\nproperty P\ncontext C : colour",
        "m.roqme:3:13: unknown type colour (declare it with 'type colour : enum {…}' before this context)",
    ),
    ("roqme M\nproperty P\ncontext C : enum {A, A}", "m.roqme:3:22: enum literal A appears twice in C"),
    ("roqme M\nproperty P\ncontext C : enum {}", "m.roqme:3:19: expected an enum literal after '{', found '}'"),
    (
        "roqme M\nproperty P\ntimer T : 30sec",
        "m.roqme:3:9: expected ':=' or 'offset' or 'onetime' or 'paused' after 'T', found ':'",
    ),
    ("roqme M\nimport other.roqme\nproperty P", "m.roqme:2:8: cannot import other.roqme: no such model file"),
    (
        HEAD + "observation O : avg(N, 2.5) > 2 reinforces P",
        "m.roqme:7:24: the window of avg is a whole number of updates (3) or a time (5 minutes)",
    ),
    (
        HEAD + "observation O : foo(N) reinforces P",
        "m.roqme:7:17: unknown function foo(…) (functions: avg, min, max, count, sum, increasing, decreasing, "
        "stable, pow, sqrt, exp, abs, first, last, at, size, isEmpty, includes, period, update, eventWhen)",
    ),
    (
        HEAD + "observation O : every B reinforces P",
        "m.roqme:7:17: the 'every' pattern operator is not supported (observations re-arm after every match anyway)",
    ),
    (HEAD + "observation O : B reinforces Q", "m.roqme:7:30: observation O reinforces unknown property Q"),
    (
        HEAD + "observation O : B reinforces P mild",
        "m.roqme:7:32: expected a strength (verylow, low, medium, high, veryhigh) after 'P', found 'mild'",
    ),
    (
        HEAD + "observation O : B reinforces",
        "m.roqme:7:29: expected a property name after 'reinforces', found the end of the file",
    ),
    (
        HEAD + "observation O : B",
        "m.roqme:7:18: expected an action (reinforces, undermines, sets, clears, starts, stops, resumes) after 'B', "
        "found the end of the file",
    ),
    (HEAD + "observation O : X reinforces P", "m.roqme:7:17: unknown context X"),
    (
        HEAD + "observation O : N + 1 reinforces P",
        "m.roqme:7:17: a number value cannot stand as a pattern: use update(…) or compare it",
    ),
    (HEAD + "observation O : eventWhen(N) reinforces P", "m.roqme:7:27: eventWhen needs a boolean, but N is number"),
    (
        HEAD + "observation O : !update(B) reinforces P",
        "m.roqme:7:18: the pattern operator 'update' cannot be used in a value; only values and & | ! "
        "comparisons and arithmetic can",
    ),
    (HEAD + "observation O : B while(N) reinforces P", "m.roqme:7:25: the while condition must be boolean, not number"),
    (
        HEAD + "observation O : B while(B and B) reinforces P",
        "m.roqme:7:25: the pattern operator 'and' cannot be used in the while condition; only values and & | ! "
        "comparisons and arithmetic can",
    ),
    (
        HEAD + "observation O : B repeat(0) reinforces P",
        "m.roqme:7:26: repeat needs a whole number of times ≥ 1, not 0",
    ),
    (
        HEAD + "observation O : B repeat(1.5) reinforces P",
        "m.roqme:7:26: repeat needs a whole number of times ≥ 1, not 1.5",
    ),
    (
        HEAD + "observation O : S = S::MAYBE reinforces P",
        "m.roqme:7:24: S has no literal MAYBE (expected one of ON, OFF)",
    ),
    (HEAD + "observation O : S = T::ON reinforces P", "m.roqme:7:21: T is not an enum type"),
    (HEAD + "observation O : S = N reinforces P", "m.roqme:7:17: '=' compares enum S with number"),
    (HEAD + "observation O : N > B reinforces P", "m.roqme:7:21: '>' needs a number operand, not boolean"),
    (
        HEAD + "observation O : E & B reinforces P",
        "m.roqme:7:17: E is an eventtype and has no value: use it as a pattern or in update()",
    ),
    (
        HEAD + "observation O : B and reinforces P",
        "m.roqme:7:23: expected a pattern or a value after 'and', found 'reinforces'",
    ),
    (HEAD + "observation O : (B reinforces P", "m.roqme:7:20: expected ')' after 'B', found 'reinforces'"),
    (HEAD + "observation O : B @ B reinforces P", "m.roqme:7:19: unexpected character '@'"),
    (
        HEAD + "observation O : B reinforces P\nobservation O : B reinforces P",
        "m.roqme:8:13: O is already declared as an observation",
    ),
    (HEAD + "observation O : B reinforces P /* unterminated", "m.roqme:7:32: unterminated comment: '/*' without '*/'"),
    (HEAD + "observation P : B reinforces P", "m.roqme:7:13: P is already declared as a property"),
    (HEAD + "context C : number := C + 1", "m.roqme:7:23: C is used in its own definition"),
    (
        HEAD + "observation O : B clears N",
        "m.roqme:7:26: observation O clears N, a context: only a property or a beliefvar holds evidence",
    ),
    (
        HEAD + "beliefvar F\nobservation O : update(F < 0.5) reinforces P",
        "m.roqme:8:24: this value reads no context, so it never changes by an update: use it as a condition "
        "(X while(…)) or read a context",
    ),
    (
        HEAD + "observation O : B { undermines P; sets v := 1 }",
        "m.roqme:7:40: observation O sets v, which is undeclared: only a var can be set",
    ),
    (
        HEAD + 'timer T := schedule("0, 9, *, *")',
        "m.roqme:7:21: bad schedule: expected 5 or 6 comma-separated fields (minutes, hours, days, months, "
        "weekdays[, seconds]), found 4",
    ),
    (
        HEAD + "observation O : N'avg(3, B, B) > 1 reinforces P",
        "m.roqme:7:17: avg takes a context, then optionally a window (a count or a time) and a condition",
    ),
]


@pytest.mark.parametrize(("text", "message"), CASES, ids=[f"case{i}" for i in range(len(CASES))])
def test_malformed_model_is_rejected_with_its_message(text, message):
    with pytest.raises(ModelError) as caught:
        parse_model(text, "m.roqme")
    assert str(caught.value) == message


def test_errors_in_a_model_file_name_the_file(tmp_path):
    path = tmp_path / "broken.roqme"
    path.write_text("roqme M\nproperty P\ncontext C : boolean\nobservation O : C reinforces\n", encoding="utf-8")
    with pytest.raises(ModelError, match=r"^broken\.roqme:4:29: expected a property name after 'reinforces'"):
        load_model(path)


def test_missing_model_file_and_unknown_bundled_name(tmp_path):
    with pytest.raises(ModelError, match=r"missing\.roqme:1:1: cannot read the file"):
        load_model(tmp_path / "missing.roqme")
    with pytest.raises(ModelError, match=r"no bundled model named 'nope' \(bundled: clarc, kiosk_pace\)"):
        load_model("nope")


def test_comments_units_and_reference_bounds_are_read():
    model = parse_model(
        "// line comment\nroqme M /* block\n comment */\n"
        "property A reference 1 survival 30 sec\nproperty B reference 0 survival 2h\n"
        "property C survival 500ms\nproperty D\n",
        "m.roqme",
    )
    assert [model.properties[name].survival for name in "ABCD"] == [30.0, 7200.0, 0.5, None]
    assert model.properties["A"].prior == 0.99 and model.properties["B"].prior == 0.01
    assert model.properties["D"].reference == 0.5


def test_a_term_nested_without_end_is_one_line_not_a_crash():
    text = HEAD + "observation O : eventWhen(" + "N + " * 5000 + "1 > 2) reinforces P"
    with pytest.raises(ModelError, match=r"^m\.roqme:7:1: O nests operators more than 200 levels deep"):
        parse_model(text, "m.roqme")
    # parentheses alone add no level
    parse_model(HEAD + "observation O : " + "(" * 5000 + "B" + ")" * 5000 + " reinforces P", "m.roqme")
