"""The bad files of the issue, through the real command lines: each is one `file:line:col: problem`
line on stderr and exit status 2 (no traceback, no hang, nothing half-loaded); `kiosk validate` and
`kiosk run` refuse the same questionnaires."""

from __future__ import annotations

import pytest
import yaml

from kiosk.core.questionnaire import bundled_path
from tests.kiosk.command_line import ROOT, kiosk, kiosk_run, one_line, write

BOMB = "".join(f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 9) if i else 'lol'}]\n" for i in range(10))


def portuguese_only() -> str:
    """The bundled questionnaire with every English text moved to Portuguese (a language the kiosk's
    screens do not have) and the rest dropped."""
    data = yaml.safe_load(bundled_path().read_text(encoding="utf-8"))

    def portuguese(value):
        if isinstance(value, dict):
            if "en" in value and set(value) <= {"en", "es", "fr", "de"}:
                return {"pt": portuguese(value["en"])}
            return {key: portuguese(inner) for key, inner in value.items()}
        return [portuguese(inner) for inner in value] if isinstance(value, list) else value

    data = portuguese(data)
    data["languages"] = ["pt"]
    return yaml.safe_dump(data, allow_unicode=True, sort_keys=False)


@pytest.mark.slow  # a subprocess
@pytest.mark.parametrize(
    ("name", "content", "where"),
    [
        ("bomb.yaml", BOMB, "bomb.yaml:7:5: aliases expand the file to more than 200,000 values"),
        ("deep.yaml", "items:\n" + "  " * 1 + "- " + "[" * 5000 + "]" * 5000 + "\n", "deep.yaml:2:"),
        ("nul.yaml", b"id: barthel\x00\n", "nul.yaml:1:12: a NUL byte"),
        ("latin.yaml", "title: {en: Índice}\n".encode("latin-1"), "latin.yaml:1:"),
        ("pt.yaml", portuguese_only(), "pt.yaml:"),
    ],
)
def test_kiosk_run_and_validate_refuse_the_same_questionnaires(tmp_path, name, content, where):
    questionnaire = write(tmp_path, name, content)
    config = write(tmp_path, "config.yaml", f"questionnaire: {questionnaire}\n")
    run = kiosk_run(config, tmp_path, "--no-remote")
    assert one_line(run, f"kiosk run: {questionnaire}:").count(where) == 1
    validated = kiosk("validate", str(questionnaire), cwd=tmp_path)
    assert validated.returncode in (1, 2) and where in validated.stdout, validated.stdout
    if name == "pt.yaml":
        assert "language 'pt'" in validated.stdout and validated.returncode == 1


@pytest.mark.slow  # a subprocess
def test_an_empty_item_list_is_reported_as_such(tmp_path):
    data = yaml.safe_load(bundled_path().read_text(encoding="utf-8"))
    data["items"] = []
    path = write(tmp_path, "empty.yaml", yaml.safe_dump(data, allow_unicode=True, sort_keys=False))
    done = kiosk("validate", str(path), cwd=tmp_path)
    assert done.returncode == 1 and done.stdout.strip().splitlines() == [
        f"{path}:{done.stdout.split(':')[1]}:{done.stdout.split(':')[2]}: items is empty: list at least one"
    ]


@pytest.mark.slow  # a subprocess
@pytest.mark.parametrize(
    ("content", "where"),
    [
        (
            '{"model": "clarc", "events": [{"t": ' + "9" * 5000 + ', "set": {"PersonDetected": true}}]}',
            "trace.json:1:37: the number 9999",
        ),
        ('{"model": "clarc", "events": [{"t": NaN, "set": {"PersonDetected": true}}]}', "trace.json:1:37: NaN"),
        ('{"model": "clarc", "model": "clarc", "events": []}', "trace.json:1:20: duplicate key 'model'"),
        (
            '{"model": "clarc", "events": [{"t": 0, "set": {"PersonDetected": true}}, '
            '{"t": 10000000, "set": {"PersonDetected": false}}]}',
            "would take 10,000,001 samples",
        ),
    ],
)
def test_kiosk_qos_replay_refuses_bad_traces(tmp_path, content, where):
    trace = write(tmp_path, "trace.json", content)
    one_line(kiosk("qos", "replay", str(trace), cwd=tmp_path), where)


@pytest.mark.slow  # a subprocess
@pytest.mark.parametrize(
    ("change", "where"),
    [
        (("start_at: 10", "start_at: 99999999999999"), "patient.yaml:10:11: start_at: 99999999999999 is greater"),
        (("start_at: 10", "start_at: .nan"), "patient.yaml:10:11: '.nan' is not a finite number"),
        (("start_at: 10", "start_at: 10\nstart_at: 11"), "patient.yaml:11:1: duplicate key 'start_at'"),
    ],
)
def test_kiosk_replay_refuses_bad_scripts(tmp_path, change, where):
    text = (ROOT / "recordings/patients/barthel6.yaml").read_text(encoding="utf-8")
    assert change[0] in text
    script = write(tmp_path, "patient.yaml", text.replace(*change, 1))
    one_line(kiosk("replay", str(script), cwd=tmp_path), where)


@pytest.mark.slow  # a subprocess
def test_a_policy_that_is_not_utf8_stops_kiosk_run_with_one_line(tmp_path):
    policy = write(tmp_path, "policy.yaml", "rules: []\n# réglée\n".encode("latin-1"))
    config = write(tmp_path, "config.yaml", f"adaptation_policy: {policy}\n")
    one_line(kiosk_run(config, tmp_path, "--no-remote"), f"{policy}:2:4: not UTF-8 text (byte 0xe9)")


@pytest.mark.slow  # a subprocess
def test_duplicate_keys_in_site_remote_profiles_are_refused(tmp_path):
    profiles = write(tmp_path, "site.yaml", "profiles:\n  - name: a\n    name: b\n")
    one_line(kiosk("devices", "--profiles", str(profiles), cwd=tmp_path), "site.yaml:3:5: duplicate key 'name'")
