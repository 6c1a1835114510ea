"""`kiosk replay` of a patient in a room where voice fails (recordings/patients/voice_room.yaml):
the kiosk steers her to touch early, on the room's own measure, and the QoS trace is unchanged."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from kiosk.commands.replay import ScriptError, load_script, run_script

ROOT = Path(__file__).resolve().parents[3]
ROOM = ROOT / "recordings/patients/voice_room.yaml"


def test_voice_failing_in_the_room_steers_to_touch_before_voice_interaction_quality_would():
    script = load_script(ROOM)
    adapted = run_script(script).to_dict()
    switched = [(a["t"], a["name"]) for a in adapted["adaptations"] if a["active"]]
    assert [name for _, name in switched] == ["voice_room", "voice_off"]
    bathing = next(a for a in adapted["answers"] if a["item"] == "bathing")
    assert switched[0][0] < bathing["t"]  # on during the second question, before its answer
    assert "VoiceHeard" in adapted["adaptations"][0]["reason"]
    plain = run_script(dataclasses.replace(script, adaptation=False))
    assert [e.to_dict() for e in run_script(script).trace.events] == [e.to_dict() for e in plain.trace.events]


def test_without_the_unheard_speech_the_room_is_not_blamed(tmp_path):
    text = ROOM.read_text(encoding="utf-8").replace("      - {do: unheard, after: 3}\n", "")
    text = text.replace("    incidents:\n", "")
    path = tmp_path / "patient.yaml"
    path.write_text(text, encoding="utf-8")
    names = [a["name"] for a in run_script(load_script(path)).to_dict()["adaptations"]]
    assert "voice_room" not in names


def test_a_voice_answer_once_voice_is_steered_away_cannot_happen(tmp_path):
    text = ROOM.read_text(encoding="utf-8").replace(
        "{item: grooming, attempt: 1, channel: touch, option: 2, after: 5}",
        '{item: grooming, attempt: 1, channel: voice, say: "independent", after: 5}',
    )
    path = tmp_path / "patient.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ScriptError, match=r"the session ignored the answer declared on attempt 1 \(voice_off\)"):
        run_script(load_script(path))
