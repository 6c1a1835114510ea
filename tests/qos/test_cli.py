"""`python -m qos replay` and `kiosk qos`: output, plot, and one clear line with exit 2 on bad input."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from kiosk.commands import qos as qos_cli
from qos import load_trace, replay
from qos.cli import main

ROOT = Path(__file__).resolve().parents[2]
TABLE4 = ROOT / "recordings" / "testbench" / "barthel4_table4.yaml"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=ROOT)


def test_python_m_qos_replay_json_is_the_replay_result():
    done = run("-m", "qos", "replay", str(TABLE4), "--json")
    assert done.returncode == 0 and done.stderr == ""
    assert json.loads(done.stdout) == json.loads(json.dumps(replay(TABLE4)))


def test_kiosk_qos_replay_behaves_like_python_m_qos(capsys):
    assert qos_cli.main(["replay", str(TABLE4), "--json", "--sample-period", "5"]) == 0
    assert json.loads(capsys.readouterr().out) == json.loads(json.dumps(replay(TABLE4, sample_period=5)))


def test_human_output_has_the_table_and_the_observations_over_time(capsys):
    assert main(["replay", str(TABLE4)]) == 0
    out = capsys.readouterr().out
    assert "Performance              0.0773  0.6679  0.3241  0.2098  0.1677" in out
    assert "t=     890 s  O2 O7 O14" in out


def test_plot_writes_a_png(tmp_path, capsys):
    target = tmp_path / "b4.png"
    assert main(["replay", str(TABLE4), "--plot", str(target)]) == 0
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and target.stat().st_size > 10_000
    missing = tmp_path / "no" / "such" / "dir.png"
    assert main(["replay", str(TABLE4), "--plot", str(missing)]) == 2
    assert capsys.readouterr().err == f"python -m qos replay: cannot write {missing}: No such file or directory\n"


def test_plot_replaces_a_world_readable_png_with_an_owner_only_one(tmp_path):
    # the plot's title is the trace description, which names the patient
    target = tmp_path / "old.png"
    target.write_bytes(b"old")
    target.chmod(0o644)
    assert main(["replay", str(TABLE4), "--plot", str(target)]) == 0
    assert target.stat().st_mode & 0o777 == 0o600 and target.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize(
    ("trace", "model", "message"),
    [
        (
            "model: clarc\nevents:\n  - {t: 1, set: {Mood: happy}}\n",
            None,
            "python -m qos replay: {dir}/t.yaml: events[0]: context 'Mood' is not in model CLARC",
        ),
        (
            "model: broken.roqme\nevents: []\n",
            "roqme B\nproperty P survival 10\n",
            "python -m qos replay: broken.roqme:2:21: expected a time such as 100min, 30 seconds or 2 hours after 'survival', "
            "found '10'",
        ),
    ],
)
def test_bad_trace_or_model_exits_2_with_one_line(tmp_path, trace, model, message):
    (tmp_path / "t.yaml").write_text(trace, encoding="utf-8")
    if model:
        (tmp_path / "broken.roqme").write_text(model, encoding="utf-8")
    done = run("-m", "qos", "replay", str(tmp_path / "t.yaml"))
    assert (done.returncode, done.stdout) == (2, "")
    assert done.stderr == message.format(dir=tmp_path) + "\n"


def test_a_sample_period_too_small_for_the_trace_is_one_line_not_an_endless_replay(capsys):
    # TABLE4 lasts 1000 s: 1e-7 s would be 10 billion samples (before the cap: an endless replay)
    assert main(["replay", str(TABLE4), "--sample-period", "1e-7"]) == 2
    err = capsys.readouterr().err
    assert (
        err.startswith(f"python -m qos replay: {TABLE4}: a sample period of 1e-07 s over the trace's ")
        and "(at most 100,000); use a longer sample period\n" in err
        and err.count("\n") == 1
    )


def test_bad_arguments_exit_2(capsys):
    with pytest.raises(SystemExit) as exited:
        main(["replay", str(TABLE4), "--sample-period", "0"])
    assert exited.value.code == 2
    assert "must be a positive number of seconds" in capsys.readouterr().err


def test_kiosk_qos_trace_prints_a_stored_sessions_trace_that_replays_to_its_metrics(tmp_path, capsys):
    from kiosk.commands.replay import load_script, run_script
    from kiosk.store.database import Store

    data = tmp_path / "data"
    with Store.open(data) as store:
        result = run_script(load_script(ROOT / "recordings/patients/barthel3.yaml"), store=store)
        stored = store.session(result.session.id)
    assert qos_cli.main(["trace", result.session.id, "--data-dir", str(data)]) == 0
    printed = tmp_path / "printed.yaml"
    printed.write_text(capsys.readouterr().out)
    assert main(["replay", str(printed), "--json"]) == 0
    replayed = json.loads(capsys.readouterr().out)
    assert stored.metrics and len(load_trace(printed).events) == len(stored.trace)
    for name, value in stored.metrics[-1].metrics.items():
        assert replayed["metrics"][name]["last"] == pytest.approx(value, abs=1e-12)


@pytest.mark.slow  # a subprocess
@pytest.mark.parametrize("command", [["-m", "qos"], ["-m", "kiosk", "qos"]])
def test_a_reader_closing_the_pipe_early_is_not_an_error(command):
    """`… | head -c 0`: the reader is gone before anything is written; no traceback, exit 0."""
    child = subprocess.Popen(
        [sys.executable, *command, "replay", str(TABLE4)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT
    )
    child.stdout.close()
    assert child.wait(timeout=60) == 0
    assert child.stderr.read() == b""


def test_check_says_what_a_model_holds_or_where_it_is_wrong(tmp_path, capsys):
    assert main(["check", "kiosk_pace"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("model KioskPace: OK\n")
    assert "derived contexts: Answered, AnswerTime, SlowStreak, Slowing, AnswersPerFiveMinutes" in out
    assert "timers: Silence" in out and "imports: clarc.roqme" in out
    (tmp_path / "bad.roqme").write_text(
        "roqme X\nproperty P\ncontext A : boolean\nobservation O : A reinforces Q\n", encoding="utf-8"
    )
    done = run("-m", "kiosk", "qos", "check", str(tmp_path / "bad.roqme"))
    assert (done.returncode, done.stdout) == (2, "")
    assert done.stderr == "kiosk qos check: bad.roqme:4:30: observation O reinforces unknown property Q\n"
