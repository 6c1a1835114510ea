"""The kiosk_pace example model and its scripted patient: what a QoS engineer is told it shows."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from kiosk.commands import qos as qos_cli
from qos import Engine, load_model, load_trace, replay

ROOT = Path(__file__).resolve().parents[2]
SLOW_PATIENT = ROOT / "recordings" / "qos" / "slow_patient.yaml"


def _fired_at(result: dict) -> dict:
    return {entry["t"]: entry["observations"] for entry in result["fired"]}


def test_the_slow_patient_shows_slow_answers_silence_and_a_fresh_start(capsys):
    assert qos_cli.main(["replay", str(SLOW_PATIENT), "--json"]) == 0
    fired = _fired_at(json.loads(capsys.readouterr().out))
    assert [t for t, names in fired.items() if "SlowAnswers" in names] == [164, 262]
    assert [t for t, names in fired.items() if "SlowingDown" in names] == [97, 129, 164, 262]
    # the Silence timer started by the question at 180 fires on the trace's clock, in a batch of its own
    assert fired[240] == ["Silent"]
    assert "FreshStart" in fired[300]
    # the five-minute window that opened with the first answer (t=21) closes at 321 with 9 answers
    assert fired[321] == ["Brisk"]
    # the CLARC observations are all still there (the model imports clarc.roqme)
    assert fired[10] == ["O2", "O8"] and "O6" in fired[245]


def test_the_replay_reports_belief_variables_apart_from_the_published_properties(capsys):
    result = replay(SLOW_PATIENT)
    assert list(result["metrics"]) == ["Performance", "Interaction", "VoiceInteractionQuality"]
    fatigue = result["beliefs"]["Fatigue"]
    assert fatigue["min"] == 0.2 and fatigue["max"] > 0.5 and fatigue["last"] == 0.2  # cleared by the restart
    assert qos_cli.main(["replay", str(SLOW_PATIENT)]) == 0
    assert "belief variables (not published):\nFatigue" in capsys.readouterr().out


@pytest.mark.slow  # a subprocess
def test_the_example_replays_identically_from_python_and_from_the_shell():
    done = subprocess.run(
        [sys.executable, "-m", "qos", "replay", str(SLOW_PATIENT), "--json"], capture_output=True, text=True, cwd=ROOT
    )
    assert done.returncode == 0 and done.stderr == ""
    assert (
        json.loads(done.stdout)
        == json.loads(json.dumps(replay(SLOW_PATIENT)))
        == json.loads(json.dumps(replay(SLOW_PATIENT)))
    )


def test_silence_and_slow_answers_lower_the_metrics_they_should():
    model = load_model("kiosk_pace")
    engine = Engine(model)
    engine.update(0, set={"PersonDetected": True})
    engine.update(5, emit=["QuestionAsked"])
    before = engine.metrics(5)["Interaction"]
    (silence,) = engine.advance(65)
    assert (silence.t, silence.fired) == (65, ["Silent"]) and silence.metrics["Interaction"] < before
    assert silence.beliefs["Fatigue"] > 0.2
    # an answer before the minute is up stops the timer: no silence
    engine.update(70, emit=["QuestionAsked"])
    engine.update(80, set={"FirstAttemptAnswered": True})
    assert engine.contexts["AnswerTime"] == 10
    assert all("Silent" not in result.fired for result in engine.advance(500))


def test_the_models_descriptions_are_there_for_engineers():
    model = load_model("kiosk_pace")
    assert model.description.startswith("The kiosk's pace")
    assert "longer than SlowAnswer" in model.contexts["SlowStreak"].description
    assert model.variables["SlowAnswer"].initial == 15
    assert load_trace(SLOW_PATIENT).model == "kiosk_pace"


def test_timers_fire_at_their_own_times_whatever_the_sample_period():
    fired = [replay(SLOW_PATIENT, sample_period=period)["fired"] for period in (1, 7, 0.5, 100)]
    assert fired[0] == fired[1] == fired[2] == fired[3]
