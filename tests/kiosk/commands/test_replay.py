"""`kiosk replay`: scripted patients through the real session, and clear errors for bad scripts."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from kiosk.commands.replay import ScriptError, load_script, main, run_script

ROOT = Path(__file__).resolve().parents[3]
PATIENTS = sorted((ROOT / "recordings/patients").glob("*.yaml"))

GOOD = """\
patient: P-T1
start_at: 2
timing: {attempt_window_s: 20, between_questions_s: 2}
questions:
  - {attempt: 1, channel: touch, option: 3, after: 4}
  - {attempt: 1, channel: touch, option: 2, after: 4}
  - {attempt: 1, channel: touch, option: 2, after: 4}
  - {attempt: 1, channel: touch, option: 3, after: 4}
  - {attempt: 1, channel: touch, option: 3, after: 4}
  - {attempt: 1, channel: touch, option: 3, after: 4}
  - {attempt: 1, channel: touch, option: 3, after: 4}
  - {attempt: 1, channel: touch, option: 4, after: 4}
  - {attempt: 1, channel: touch, option: 4, after: 4}
  - {attempt: 1, channel: touch, option: 3, after: 4}
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "patient.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_there_are_test_bench_and_other_patients():
    names = {p.stem for p in PATIENTS}
    assert {f"barthel{n}" for n in range(1, 7)} <= names
    assert len(names) >= 9


@pytest.mark.parametrize("path", PATIENTS, ids=lambda p: p.stem)
def test_every_committed_patient_replays_to_the_end(path):
    result = run_script(load_script(path))
    assert result.session.finished
    data = result.to_dict()
    assert data["score"]["total"] == sum(a["points"] for a in data["answers"])
    assert len(data["answers"]) + len(data["not_answered"]) == 10


def test_replay_json_output(tmp_path, capsys):
    assert main([str(write(tmp_path, GOOD)), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["score"] == {"total": 100, "complete": True, "max_total": 100, "band": "independent"}
    assert [a["t"] for a in data["answers"]][:2] == [2 + 2 + 4, 8 + 2 + 4]
    assert set(data["qos"]["metrics"]) == {"Performance", "Interaction", "VoiceInteractionQuality"}


def test_replay_writes_its_trace_for_qos_replay(tmp_path, capsys):
    from qos import load_trace, replay

    out = tmp_path / "trace.yaml"
    assert main([str(ROOT / "recordings/patients/barthel4.yaml"), "--trace", str(out), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert replay(load_trace(out)) == printed["qos"]
    assert out.stat().st_mode & 0o777 == 0o600


def test_spanish_voice_patient_answers_through_the_speech_matcher():
    result = run_script(load_script(ROOT / "recordings/patients/spanish_voice.yaml"))
    answers = result.session.answers
    assert all(a.channel.value == "voice" for a in answers.values())
    assert answers["mobility"].option == 4  # "la cuarta"
    assert answers["dressing"].option == 2
    assert result.session.language == "es"
    # "la tres" on the selecting check is answer number 3, as asked
    assert [(e.question_id, e.option, e.correct) for e in result.events if type(e).__name__ == "PracticeAnswered"] == [
        ("practice_hear", 2, True),
        ("practice_read", 1, True),
        ("practice_select", 3, True),
    ]


def test_adaptation_switches_voice_off_but_never_changes_the_qos_trace():
    script = load_script(ROOT / "recordings/patients/voice_dropout.yaml")
    adapted = run_script(script)
    plain = run_script(dataclasses.replace(script, adaptation=False))
    assert [a["name"] for a in adapted.to_dict()["adaptations"]] == ["voice_off"]
    assert not plain.to_dict()["adaptations"]
    assert [e.to_dict() for e in adapted.trace.events] == [e.to_dict() for e in plain.trace.events]


def test_a_voice_answer_after_voice_off_cannot_happen_and_the_script_says_where(tmp_path):
    text = (ROOT / "recordings/patients/voice_dropout.yaml").read_text()
    text = text.replace(
        "{item: stairs, attempt: 1, channel: remote, option: 2, after: 5}",
        '{item: stairs, attempt: 1, channel: voice, say: "independent", after: 5}',
    )
    path = write(tmp_path, text)
    with pytest.raises(
        ScriptError,
        match=r"patient\.yaml:21:5: the session ignored the answer declared on "
        r"attempt 1 \(voice_off\)",
    ):
        run_script(load_script(path))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("patient: P-T1", "patient: P-T1\ncolour: red"), r":2:1: unknown key 'colour'"),
        (
            (
                "{attempt: 1, channel: touch, option: 3, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
                "{attempt: 3, channel: touch, option: 3, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
            ),
            r":5:15: questions\[0\]\.attempt: 3 is not one of \[1, 2, 'none', 'any'\]",
        ),
        (
            (
                "option: 3, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
                "say: hello, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
            ),
            r":5:\d+: 'say' needs channel voice, not touch",
        ),
        (
            (
                "channel: touch, option: 3, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
                "channel: voice, say: purple elephants, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
            ),
            r":5:\d+: on 'feeding', 'purple elephants' is not an answer",
        ),
        (
            ("  - {attempt: 1, channel: touch, option: 3, after: 4}\n", ""),
            r":5:3: the script has 9 questions; the questionnaire has 10",
        ),
        (
            (
                "{attempt: 1, channel: touch, option: 3, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
                "{attempt: 1, channel: touch, option: 5, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
            ),
            r":5:\d+: 'feeding' has 3 options, not 5",
        ),
        (
            (
                "{attempt: 1, channel: touch, option: 3, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
                "{item: bathing, attempt: 1, channel: touch, option: 3, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
            ),
            r":5:\d+: question 1 of the questionnaire is 'feeding', not 'bathing'",
        ),
        (
            (
                "{attempt: 1, channel: touch, option: 3, after: 4}\n  - {attempt: 1, channel: touch, option: 2",
                "{attempt: none, channel: touch}\n  - {attempt: 1, channel: touch, option: 2",
            ),
            r":5:\d+: questions\[0\] is not answered \(attempt: none\) but gives 'channel'",
        ),
        (("questions:\n", "questions: [\n"), r":5:3: YAML syntax: expected the node content, but found '-'"),
        (("start_at: 2", "start_at: 2\nstart_at: 3"), r":3:1: duplicate key 'start_at'"),
        (("attempt_window_s: 20", "attempt_window_s: 0"), r":3:\d+: timing\.attempt_window_s: 0 is less than or equal"),
    ],
)
def test_a_bad_script_is_one_message_with_file_line_and_column_and_exit_2(tmp_path, capsys, change, message):
    old, new = change
    assert old in GOOD
    path = write(tmp_path, GOOD.replace(old, new, 1))
    assert main([str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    err = captured.err.strip()
    assert "\n" not in err and "Traceback" not in err
    assert err.startswith(str(path) + ":")
    assert __import__("re").search(message, err), err


def test_an_answer_declared_on_attempt_one_after_its_window_is_an_error(tmp_path, capsys):
    path = write(tmp_path, GOOD.replace("option: 3, after: 4}", "option: 3, after: 21}", 1))
    assert main([str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{path}:5:5: the answer declared on attempt 1 (21 s after it opened) never happened" in err


def test_a_script_that_never_continues_after_calling_the_doctor_is_an_error(tmp_path, capsys):
    text = GOOD.replace(
        "  - {attempt: 1, channel: touch, option: 3, after: 4}\n",
        "  - attempt: none\n    incidents:\n      - {do: call_doctor, after: 3}\n",
        1,
    )
    assert main([str(write(tmp_path, text))]) == 2
    assert (
        "the script ends while the session waits (doctor called, no clinician continue) at t=7 s"
        in capsys.readouterr().err
    )


def test_a_missing_script_is_a_clear_error(tmp_path, capsys):
    assert main([str(tmp_path / "nope.yaml")]) == 2
    assert "nope.yaml:1:1: cannot read the file: No such file or directory" in capsys.readouterr().err


def test_the_script_schema_is_a_valid_json_schema():
    import jsonschema

    schema = json.loads((ROOT / "kiosk/commands/patient.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)


def test_replays_can_be_stored_for_kiosk_results(tmp_path, capsys):
    from kiosk.store.database import Store

    data = tmp_path / "data"
    assert main([str(ROOT / "recordings/patients/barthel2.yaml"), "--data-dir", str(data), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    with Store.open(data) as store:
        (summary,) = store.sessions()
        assert (summary.patient_id, summary.status, summary.answered) == ("TB-0002", "finished", 10)
        assert [(a.item_id, a.option) for a in store.session(summary.id).answers] == [
            (a["item"], a["option"]) for a in printed["answers"]
        ]


def test_a_failed_stored_replay_is_abandoned_not_left_for_the_kiosk_to_resume(tmp_path, capsys):
    from kiosk.store.database import Store

    data = tmp_path / "data"
    path = write(tmp_path, GOOD.replace("option: 3, after: 4}", "option: 3, after: 21}", 1))
    assert main([str(path), "--data-dir", str(data)]) == 2
    with Store.open(data) as store:
        (summary,) = store.sessions()
        assert summary.status == "abandoned"
        assert store.unfinished_sessions() == []


def test_replay_trace_to_an_unwritable_file_is_one_line_and_exit_2(tmp_path, capsys):
    target = tmp_path / "missing" / "trace.yaml"
    assert main([str(write(tmp_path, GOOD)), "--trace", str(target)]) == 2
    assert capsys.readouterr().err == f"kiosk replay: cannot write {target}: No such file or directory\n"


@pytest.mark.parametrize("data_dir", [False, True])
def test_a_scripted_patient_named_by_name_is_rejected_where_it_is_written(tmp_path, capsys, data_dir):
    from kiosk.store.database import PATIENT_ID

    path = write(tmp_path, GOOD.replace("patient: P-T1", 'patient: "Ann Smith"'))
    extra = ["--data-dir", str(tmp_path / "data")] if data_dir else []
    assert main([str(path), *extra]) == 2
    assert capsys.readouterr().err.startswith(f"{path}:1:10: patient: 'Ann Smith' does not match")
    # the script schema and the store accept the same ids
    schema = json.loads((ROOT / "kiosk/commands/patient.schema.json").read_text())
    assert schema["properties"]["patient"]["pattern"] == PATIENT_ID.pattern


@pytest.mark.parametrize("data_dir", [False, True])
def test_a_patient_id_ending_in_a_line_break_is_rejected(tmp_path, capsys, data_dir):
    from kiosk.store.database import PATIENT_ID

    assert PATIENT_ID.match("P-T1") and not PATIENT_ID.match("P-T1\n")  # a bare '$' let this through
    path = write(tmp_path, GOOD.replace("patient: P-T1", 'patient: "P-T1\\n"'))
    extra = ["--data-dir", str(tmp_path / "data")] if data_dir else []
    assert main([str(path), *extra]) == 2
    assert capsys.readouterr().err.startswith(f"{path}:1:10: patient: 'P-T1\\n' does not match")
    if data_dir:
        from kiosk.store.database import Store

        with Store.open(tmp_path / "data", create=False) as store:
            assert store.sessions() == []  # nothing of the script was stored
