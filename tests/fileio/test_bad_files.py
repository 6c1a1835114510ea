"""Bad files thrown at every loader of the project: generated corruptions of the real files (random
bytes, truncations, NUL bytes, wrong encodings, deep nesting, alias bombs, duplicate keys, huge
numbers, NaN) must end in success or in the loader's own error, one line naming the file, and
never in a traceback or a hang (bounded by the reader's caps in fileio.bounded, not by a timer)."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kiosk.commands.replay import load_script, run_script
from kiosk.config import load_config
from kiosk.core.adaptation import load_policy
from kiosk.core.questionnaire import bundled_path, check_questionnaire_file, load_questionnaire
from kiosk.remote.profiles import load_profiles
from qos import load_model
from qos.trace import load_trace, sample_trace

ROOT = Path(__file__).resolve().parents[2]
QUESTIONNAIRE = load_questionnaire()


def _questionnaire(path: Path) -> None:
    problems = check_questionnaire_file(path)
    try:
        load_questionnaire(path)
    except ValueError:
        assert problems, "load_questionnaire refused a file kiosk validate accepts"
        raise
    assert not problems, "kiosk validate refused a file load_questionnaire accepts"


def _script(path: Path) -> None:
    run_script(load_script(path, QUESTIONNAIRE), QUESTIONNAIRE)


def _trace(path: Path) -> None:
    sample_trace(load_trace(path))


#: loader name -> (a real file of its kind, the file name it is written under, the loader)
LOADERS: dict[str, tuple[bytes, str, Callable[[Path], object]]] = {
    "questionnaire": (bundled_path().read_bytes(), "q.yaml", _questionnaire),
    "config": (
        b'language: es\nclinician_pin: "482193"\ntiming: {attempt_window_s: 30}\nadaptation: true\n',
        "config.yaml",
        lambda p: load_config(p, environ={}),
    ),
    "policy": ((ROOT / "kiosk/core/adaptation.yaml").read_bytes(), "policy.yaml", load_policy),
    "profiles": ((ROOT / "kiosk/remote/devices.yaml").read_bytes(), "site.yaml", load_profiles),
    "script": ((ROOT / "recordings/patients/barthel6.yaml").read_bytes(), "patient.yaml", _script),
    "trace (YAML)": ((ROOT / "recordings/testbench/barthel6.yaml").read_bytes(), "trace.yaml", _trace),
    "trace (JSON)": (
        b'{"model": "clarc", "events": [{"t": 0, "set": {"PersonDetected": true}}, '
        b'{"t": 12.5, "set": {"TestState": "STARTED", "FirstAttemptAnswered": false}}]}',
        "trace.json",
        _trace,
    ),
    "model": ((ROOT / "qos/models/clarc.roqme").read_bytes(), "m.roqme", load_model),
}

BOMB = b"".join(b"l%d: &l%d [%s]\n" % (i, i, b",".join([b"*l%d" % (i - 1)] * 9) if i else b'"lol"') for i in range(10))


def _corrupt(good: bytes, data: st.DataObject) -> bytes:
    """One generated corruption of a good file."""
    kind = data.draw(
        st.sampled_from(
            [
                "random",
                "truncate",
                "nul",
                "latin1",
                "utf16",
                "deep",
                "deep_block",
                "bomb",
                "duplicate",
                "huge",
                "nan",
                "replace",
            ]
        )
    )
    at = data.draw(st.integers(0, len(good)))
    number = re.compile(rb"(?<![\w.])\d+(?:\.\d+)?(?![\w.])")
    numbers = list(number.finditer(good))
    if kind == "random":
        return data.draw(st.binary(max_size=3000))
    if kind == "truncate":
        return good[:at]
    if kind == "nul":
        return good[:at] + b"\0" + good[at:]
    if kind == "latin1":
        return good[:at] + "é".encode("latin-1") + good[at:]
    if kind == "utf16":
        return good.decode("utf-8").encode(data.draw(st.sampled_from(["utf-16", "utf-16-le", "utf-32"])))
    if kind == "deep":
        depth = data.draw(st.integers(30, 100_000))
        return good[:at] + b"[" * depth + b"1" + b"]" * depth + good[at:]
    if kind == "deep_block":
        return b"".join(b"  " * i + b"k%d:\n" % i for i in range(data.draw(st.integers(30, 3000))))
    if kind == "bomb":
        return BOMB + good
    if kind == "duplicate":
        first_line = good.split(b"\n")[
            next(i for i, line in enumerate(good.split(b"\n")) if line and not line.startswith(b"#"))
        ]
        return good + b"\n" + first_line + b"\n"
    if kind in ("huge", "nan") and numbers:
        target = numbers[data.draw(st.integers(0, len(numbers) - 1))]
        replacement = (
            b"9" * data.draw(st.integers(16, 50_000))
            if kind == "huge"
            else data.draw(st.sampled_from([b".nan", b"NaN", b".inf", b"-.inf", b"Infinity", b"1e999"]))
        )
        return good[: target.start()] + replacement + good[target.end() :]
    chunk = data.draw(st.binary(min_size=1, max_size=40))
    return good[:at] + chunk + good[at + len(chunk) :]


@pytest.mark.parametrize("loader", list(LOADERS))
@settings(
    max_examples=40,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(data=st.data())
def test_a_bad_file_is_one_line_naming_it_or_loads(tmp_path, loader, data):
    good, name, load = LOADERS[loader]
    path = tmp_path / name
    path.write_bytes(_corrupt(good, data))
    try:
        load(path)
    except ValueError as error:  # every loader's error is a ValueError with the position first
        message = str(error)
        assert "\n" not in message, message
        assert re.match(rf"{re.escape(str(path.name))}:\d+:\d+: \S|{re.escape(str(path))}(:\d+:\d+)?: \S", message), (
            message
        )


@pytest.mark.parametrize("loader", list(LOADERS))
def test_the_real_files_still_load(tmp_path, loader):
    good, name, load = LOADERS[loader]
    (tmp_path / name).write_bytes(good)
    load(tmp_path / name)


def test_a_refused_file_is_never_echoed_back(tmp_path):
    # `kiosk validate /etc/passwd` printed the file's first line (and the rest) back: a value is
    # repeated only when short, and a whole file never
    secret = "root:x:0:0:root:/root:/bin/bash\n" * 30
    path = tmp_path / "passwd"
    path.write_text(secret, encoding="utf-8")
    (problem,) = check_questionnaire_file(path)
    assert str(problem) == (
        f"{path}:1:1: the file must be a mapping of keys (key: value lines), not a text of {len(secret) - 1:,} characters"
    )
    long_title = bundled_path().read_text(encoding="utf-8").replace("id: barthel", "id: [" + "x, " * 40 + "x]", 1)
    other = tmp_path / "long.yaml"
    other.write_text(long_title, encoding="utf-8")
    found = [str(p) for p in check_questionnaire_file(other)]
    assert any("id must be of type 'string', not a list of 41 values" in line for line in found), found
    assert not any("x, x, x" in line for line in found)
