"""`kiosk tug analyse` as outside checks run it: one JSON object per file, one per line; exit 0 when
every file was analysed (valid or not), 2 with one line naming file and line when one cannot be read."""

from __future__ import annotations

import json

import pytest

from kiosk.core.tug.families import generate
from kiosk.core.tug.landmarks import dump_pose_lines
from tests.kiosk.command_line import kiosk, one_line, write

pytestmark = pytest.mark.slow  # real processes


def sequence_file(folder, family: str, seed: int):
    sequence, truth = generate(family, seed)
    return write(folder, f"{family}-{seed}.jsonl", "\n".join(dump_pose_lines(sequence)) + "\n"), truth


def test_each_file_is_one_json_line_with_the_fields_checks_read(tmp_path):
    good, truth = sequence_file(tmp_path, "normal", 11)
    bad, _ = sequence_file(tmp_path, "never_stands", 11)
    done = kiosk("tug", "analyse", str(good), str(bad), "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 2
    first, second = (json.loads(line) for line in lines)
    assert first["file"] == str(good) and first["valid"] is True
    assert first["total_s"] == pytest.approx(truth.total_s, abs=1.0)
    assert {"onset_t", "seated_t", "phases", "reasons"} <= set(first)
    assert second["valid"] is False and second["total_s"] is None
    assert "the patient never stands up" in second["reasons"]


def test_without_json_the_result_reads_as_text(tmp_path):
    good, _ = sequence_file(tmp_path, "normal", 12)
    done = kiosk("tug", "analyse", str(good), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert f"{good}: " in done.stdout and " s, from " in done.stdout
    assert "walk back" in done.stdout and "turn seen" in done.stdout


def test_a_file_that_cannot_be_read_is_one_line_and_exit_2(tmp_path):
    good, _ = sequence_file(tmp_path, "normal", 13)
    bad = write(
        tmp_path,
        "short.jsonl",
        '{"format": "pose-landmarks/1", "fps": 30, "width": 640, "height": 480}\n'
        + '{"t": 0, "landmarks": [[0.5, 0.5, 0, 1]]}\n',
    )
    done = kiosk("tug", "analyse", str(bad), str(good), "--json", cwd=tmp_path)
    one_line(done, f'{bad}:2: "landmarks" must be null or 33 points, found 1')
    assert len(done.stdout.splitlines()) == 1 and json.loads(done.stdout)["file"] == str(good)


def test_a_missing_file_names_itself(tmp_path):
    done = kiosk("tug", "analyse", str(tmp_path / "nowhere.jsonl"), "--json", cwd=tmp_path)
    one_line(done, "nowhere.jsonl:1:1: cannot read the file")


def test_generate_writes_a_file_analyse_reads(tmp_path):
    out = tmp_path / "gen.jsonl"
    done = kiosk("tug", "generate", "frail", "--seed", "3", "-o", str(out), cwd=tmp_path)
    assert done.returncode == 0 and "true total" in done.stderr
    analysed = kiosk("tug", "analyse", str(out), "--json", cwd=tmp_path)
    assert json.loads(analysed.stdout)["valid"] is True
