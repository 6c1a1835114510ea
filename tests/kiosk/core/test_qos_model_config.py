"""`qos_model:` in the configuration: `kiosk replay` (as the kiosk) runs a QoS engineer's own model,
whose timers fire on the session's clock while nothing happens; the stored trace replays with
`kiosk qos replay` to the metrics the session stored; a bad model is refused at start."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from kiosk.config import ConfigError, load_config
from kiosk.core.qos_model import load_kiosk_model
from kiosk.store.database import Store
from qos import ModelError, load_trace

ROOT = Path(__file__).resolve().parents[3]
SCRIPT = ROOT / "recordings/patients/slow_patient.yaml"
SILENCE_S = load_kiosk_model("kiosk_pace").timers["Silence"].interval


def kiosk(*args: str, env: dict[str, str], code: int = 0) -> subprocess.CompletedProcess:
    done = subprocess.run([sys.executable, "-m", "kiosk", *args], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == code, done.stderr
    return done


def environment(tmp_path: Path, config: str) -> dict[str, str]:
    (tmp_path / "config.yaml").write_text(config)
    return dict(os.environ, KIOSK_CONFIG=str(tmp_path / "config.yaml"), HOME=str(tmp_path))


def test_kiosk_replay_of_a_slow_patient_fires_the_inactivity_timer_at_its_time(tmp_path):
    env = environment(tmp_path, "qos_model: kiosk_pace.roqme\n")
    data, trace_file = tmp_path / "data", tmp_path / "trace.yaml"
    printed = json.loads(
        kiosk("replay", str(SCRIPT), "--json", "--data-dir", str(data), "--trace", str(trace_file), env=env).stdout
    )
    trace = load_trace(trace_file)
    assert trace.model == "kiosk_pace"
    # question 8 is asked, the patient walks away: a minute later the Silence timer fires
    asks = [event.t for event in trace.events if "QuestionAsked" in event.emit]
    due = asks[7] + SILENCE_S
    assert all(event.t != due for event in trace.events), "nothing happens at the timer's time"
    assert {"t": due, "observations": ["Silent"]} in printed["qos"]["fired"]

    with Store.open(data, create=False) as store:
        (session_id,) = [row[0] for row in store._db.execute("SELECT id FROM sessions")]
        stored = store.session(session_id)
    assert (due, ("Silent",)) in [(m.t, m.fired) for m in stored.metrics]

    # the stored trace, as `kiosk qos trace` prints it, replays to what the session stored
    exported = tmp_path / "stored-trace.yaml"
    kiosk("qos", "trace", session_id, "--data-dir", str(data), "-o", str(exported), env=env)
    assert load_trace(exported).model == "kiosk_pace"
    replay = json.loads(kiosk("qos", "replay", str(exported), "--json", env=env).stdout)
    assert replay["fired"] == [{"t": m.t, "observations": list(m.fired)} for m in stored.metrics if m.fired]
    assert replay["fired"] == printed["qos"]["fired"]
    last = stored.metrics[-1]
    assert {name: stats["last"] for name, stats in replay["metrics"].items()} == pytest.approx(last.metrics, abs=1e-12)


def test_the_default_model_is_clarc_and_the_slow_patient_has_no_timer(tmp_path):
    env = environment(tmp_path, "adaptation: true\n")
    printed = json.loads(kiosk("replay", str(SCRIPT), "--json", env=env).stdout)
    observations = {name for batch in printed["qos"]["fired"] for name in batch["observations"]}
    assert observations and all(name.startswith("O") for name in observations)


def test_qos_model_paths_are_relative_to_the_configuration(tmp_path):
    model = tmp_path / "models" / "ward.roqme"
    model.parent.mkdir()
    model.write_text((ROOT / "qos/models/clarc.roqme").read_text())
    (tmp_path / "config.yaml").write_text("qos_model: models/ward.roqme\n")
    config = load_config(tmp_path / "config.yaml", environ={})
    assert config.qos_model == str(model)
    assert load_kiosk_model(config.qos_model).properties.keys() == load_kiosk_model().properties.keys()
    (tmp_path / "config.yaml").write_text("language: en\nqos_model: pace\n")
    with pytest.raises(ConfigError, match=r"config\.yaml:2:1: no bundled model named 'pace'"):
        load_config(tmp_path / "config.yaml", environ={})


@pytest.mark.parametrize(
    ("model", "message"),
    [
        (
            "roqme Broken\ncontext PersonDetected : boolean\nproperty Performance reference 0.5 survival\n",
            r"broken\.roqme:3:\d+: ",
        ),
        # well formed, but it lacks contexts the kiosk publishes: refused before any patient
        (
            "roqme Lonely\ncontext PersonDetected : boolean\nproperty Performance reference 0.5\n",
            r"broken\.roqme:1:1: the kiosk cannot run this model: it publishes TestState = STARTED",
        ),
        # declares QuestionAsked, but not as the event the kiosk emits
        ('import "clarc.roqme"\ncontext QuestionAsked : boolean\n', r"broken\.roqme:1:1: .*the event QuestionAsked"),
    ],
)
def test_a_model_the_kiosk_cannot_run_is_refused_at_start(tmp_path, model, message):
    (tmp_path / "clarc.roqme").write_text((ROOT / "qos/models/clarc.roqme").read_text())
    (tmp_path / "broken.roqme").write_text(model)
    env = environment(tmp_path, "qos_model: broken.roqme\n")
    done = kiosk("replay", str(SCRIPT), env=env, code=2)
    assert "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    assert re.search(message, done.stderr), done.stderr
    with pytest.raises(ModelError):
        load_kiosk_model(tmp_path / "broken.roqme")


def test_the_adaptation_policy_is_checked_against_the_configured_model(tmp_path):
    # Fatigue is a belief variable of kiosk_pace, not a published property: no rule may watch it
    (tmp_path / "policy.yaml").write_text(
        "rules:\n  - {name: slow_speech, metric: Fatigue, below: 0.3, count: 2, count_on: updates, "
        "recover_above: 0.5}\n"
    )
    env = environment(tmp_path, "qos_model: kiosk_pace\nadaptation_policy: policy.yaml\n")
    done = kiosk("replay", str(SCRIPT), env=env, code=2)
    assert "policy.yaml:2:33: unknown metric 'Fatigue'" in done.stderr
    assert "Interaction, Performance, VoiceInteractionQuality" in done.stderr
