"""Scripted patients that slip and patients that are slow: unsure voice answers asked back, a No,
undos (recordings/patients/voice_slips.yaml), `attempt: any` for a slow patient, and what the
longer_attempts adaptation does for one -- through the real session, QoS engine and replay driver."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from kiosk.commands.replay import ScriptError, load_script, main, run_script
from kiosk.core.adaptation import load_policy
from kiosk.core.channels import Channel
from kiosk.core.session import AnswerNotConfirmed, AnswerWithdrawn, ConfirmationAsked

ROOT = Path(__file__).resolve().parents[3]
SLIPS = ROOT / "recordings/patients/voice_slips.yaml"


def test_a_scripted_patient_can_confirm_decline_and_undo():
    result = run_script(load_script(SLIPS))
    kinds = [type(e) for e in result.events]
    assert kinds.count(ConfirmationAsked) == 4
    assert [(e.item_id, e.why) for e in result.events if isinstance(e, AnswerNotConfirmed)] == [("bathing", "declined")]
    assert [(e.item_id, e.option, e.by) for e in result.events if isinstance(e, AnswerWithdrawn)] == [
        ("grooming", 1, Channel.TOUCH),
        ("transfers", 2, Channel.VOICE),
    ]
    answers = result.session.answers
    assert (answers["feeding"].option, answers["feeding"].channel) == (3, Channel.VOICE)
    assert (answers["bathing"].option, answers["grooming"].option, answers["transfers"].option) == (2, 2, 3)
    assert answers["bladder"].attempt == 2 and answers["bladder"].channel is Channel.VOICE
    assert result.session.score().complete


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "patient.yaml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            'say: "independent"\n    after: 6\n    unsure: true',
            'say: "independent"\n    after: 6',
            r"only an unsure answer \(unsure: true\) is asked back",
        ),
        ('    confirm: {say: "yes", after: 3}\n', "", r"is unsure: say what the patient replies"),
        ('    then: {channel: voice, say: "independent", after: 4}\n', "", r"say what the patient answers next"),
        ('confirm: {say: "yes", after: 3}', 'confirm: {say: "maybe", after: 3}', r"'maybe' is not a yes or a no"),
        (
            "{item: mobility, attempt: 1, channel: touch, option: 4, after: 6}",
            "{item: mobility, attempt: 1, channel: touch, option: 4, after: 6, unsure: true}",
            r"only a voice answer can be unsure",
        ),
    ],
)
def test_a_bad_slip_is_one_message_with_file_line_and_column(tmp_path, capsys, old, new, message):
    text = SLIPS.read_text()
    assert old in text
    path = write(tmp_path, text.replace(old, new, 1))
    assert main([str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(str(path) + ":") and "Traceback" not in err
    assert __import__("re").search(message, err), err


def test_an_undo_after_the_thank_you_gap_is_refused_with_where_it_is_declared(tmp_path):
    text = SLIPS.read_text().replace("undo: {channel: touch, after: 2}", "undo: {channel: touch, after: 7}")
    with pytest.raises(ScriptError, match=r"patient\.yaml:\d+:\d+: the undo came too late"):
        run_script(load_script(write(tmp_path, text)))


def test_longer_attempts_let_a_slow_patient_answer():
    script = load_script(ROOT / "recordings/patients/slow_reader.yaml")
    policy = load_policy()
    without = replace(policy, rules=tuple(r for r in policy.rules if r.name != "longer_attempts"))
    slow = run_script(script, policy=without)
    assert len(slow.session.snapshot().not_answered) == 10  # 25 s answers, 20 s attempts
    helped = run_script(script, policy=policy)
    switched = [e for e in helped.events if type(e).__name__ == "AdaptationChanged" and e.name == "longer_attempts"]
    assert [e.active for e in switched] == [True]  # on after the first question, and it stays
    assert len(helped.session.snapshot().not_answered) == 1  # only the question before it switched on
    opened = [e for e in helped.events if type(e).__name__ == "AttemptOpened" and e.t > switched[0].t]
    assert all(e.deadline - e.t == 30 for e in opened)
