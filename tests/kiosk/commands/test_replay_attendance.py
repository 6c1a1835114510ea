"""`kiosk replay` of patients who leave: presence reports from the camera or staff, the away alert,
and the kiosk that waits for a touch after unanswered questions in a row (issues 34 and 36)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from kiosk.commands.replay import ScriptError, load_script, main, run_script
from kiosk.core.channels import PresenceSource
from kiosk.core.session import AttemptTimedOut, PersonLost, Prompt
from kiosk.store.database import Store

ROOT = Path(__file__).resolve().parents[3]
PATIENTS = ROOT / "recordings/patients"


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "patient.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_patient_who_walks_away_is_asked_at_most_two_questions_then_the_kiosk_waits(tmp_path):
    with Store.open(tmp_path / "data") as store:
        result = run_script(load_script(PATIENTS / "walked_away.yaml"), store=store)
        log = [(e.kind, e.detail) for e in store.session(result.session.id).log]
    data = result.to_dict()
    assert data["not_answered"] == ["dressing", "bowels"]  # two, not the seven left
    assert [a["kind"] for a in data["alerts"]] == ["unattended"]
    waited = data["alerts"][0]["t"]
    bladder = next(a for a in data["answers"] if a["item"] == "bladder")
    assert bladder["t"] == waited + 600 + 8  # the touch 600 s later opened bladder at once
    assert ("unattended", "2") in log and ("unattended_ended", "touch") in log
    said = [p.key for p in result.events if isinstance(p, Prompt) and p.kind == "message"]
    assert said.count("not_answered") == 1  # "Let us go on" after the first only


def test_a_patient_the_camera_sees_leave_is_not_timed_out_and_the_ward_is_alerted_after_60_s():
    result = run_script(load_script(PATIENTS / "camera_away.yaml"))
    data = result.to_dict()
    assert data["not_answered"] == [] and all(a["attempt"] == 1 for a in data["answers"])
    assert not [e for e in result.events if isinstance(e, AttemptTimedOut)]
    lost = [e for e in result.events if isinstance(e, PersonLost)]
    assert [e.source for e in lost] == [PresenceSource.CAMERA, PresenceSource.STAFF]
    assert data["alerts"] == [{"t": lost[0].t + 60, "kind": "away"}]  # the 20 s absence: none
    detected = [
        (e["t"], e["set"]["PersonDetected"]) for e in result.session.trace if "PersonDetected" in e.get("set", {})
    ]
    assert [v for _, v in detected] == [True, False, True, False, True]  # start, then each change once


def test_the_site_settings_come_from_the_script(tmp_path):
    text = (PATIENTS / "walked_away.yaml").read_text(encoding="utf-8")
    text = text.replace("start_at: 2\n", "start_at: 2\nunattended_after: off\naway_alert_after_s: 30\n")
    text = text.replace("    go_on: {channel: touch, after: 600}\n", "")
    result = run_script(load_script(write(tmp_path, text)))
    assert result.to_dict()["not_answered"] == ["dressing", "bowels"] and result.to_dict()["alerts"] == []


def test_a_kiosk_left_waiting_is_one_message_naming_where_to_go_on(tmp_path):
    text = (
        (PATIENTS / "walked_away.yaml")
        .read_text(encoding="utf-8")
        .replace("    go_on: {channel: touch, after: 600}\n", "")
    )
    with pytest.raises(ScriptError, match=r"waiting for a touch .*: give go_on at .*patient.yaml:16:5"):
        run_script(load_script(write(tmp_path, text)))


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "  - {item: feeding, attempt: 1, channel: touch, option: 3, after: 6}",
            "  - {item: feeding, attempt: 1, channel: touch, option: 3, after: 6, go_on: {after: 3}}",
            ":12:70: questions[0] is answered: the kiosk never waits after it",
        ),
        (
            "go_on: {channel: touch, after: 600}",
            "go_on: {channel: voice, after: 600}",
            ":18:22: questions[4].go_on.channel: 'voice' is not one of ['touch', 'remote', 'keyboard']",
        ),
        ("start_at: 2\n", "start_at: 2\nunattended_after: 0\n", ":10:19: unattended_after: 0 is not valid"),
    ],
)
def test_bad_attendance_keys_say_where(tmp_path, capsys, old, new, message):
    text = (PATIENTS / "walked_away.yaml").read_text(encoding="utf-8")
    assert old in text
    path = write(tmp_path, text.replace(old, new, 1))
    assert main([str(path)]) == 2
    assert capsys.readouterr().err.startswith(f"{path}{message}")


def test_go_on_declared_where_the_kiosk_never_waits_is_refused(tmp_path):
    text = (
        (PATIENTS / "walked_away.yaml")
        .read_text(encoding="utf-8")
        .replace(
            "  - {item: dressing, attempt: none}",
            "  - {item: dressing, attempt: 1, channel: touch, option: 2, after: 3}",
        )
    )
    with pytest.raises(ScriptError, match="never waited for a touch after this question"):
        run_script(load_script(write(tmp_path, text)))


def test_replay_json_lists_the_alerts(capsys):
    assert main([str(PATIENTS / "camera_away.yaml"), "--json"]) == 0
    assert [a["kind"] for a in json.loads(capsys.readouterr().out)["alerts"]] == ["away"]
