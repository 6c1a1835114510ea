"""Owner-only files: created or replaced with mode 0600, whatever mode an old file had; and the\nbounded reader every loader shares."""

from __future__ import annotations

import os
import stat

import pytest

from fileio.bounded import MAX_DEPTH, BadFile, load_json, read_text, write_private
from fileio.yamlfile import load_yaml


def world_readable(path):
    path.write_text("old, longer content that must go\n")
    path.chmod(0o644)
    return path


@pytest.mark.parametrize("data", ["text ✓\n", b"\x89PNG bytes"])
def test_write_private_replaces_an_existing_world_readable_file_with_an_owner_only_one(tmp_path, data):
    target = world_readable(tmp_path / "out")
    write_private(target, data)
    assert stat.S_IMODE(target.stat().st_mode) == 0o600
    assert target.read_bytes() == (data.encode() if isinstance(data, str) else data)


def test_write_private_creates_a_new_file_owner_only(tmp_path):
    write_private(tmp_path / "new.txt", "x")
    assert stat.S_IMODE((tmp_path / "new.txt").stat().st_mode) == 0o600


def test_write_private_to_a_missing_directory_raises_oserror(tmp_path):
    with pytest.raises(FileNotFoundError):
        write_private(tmp_path / "no" / "such.txt", "x")


# -- the bounded reader --------------------------------------------------------------------------

BOMB = "".join(f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 9) if i else 'lol'}]\n" for i in range(10))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (BOMB, "y:7:5: aliases expand the file to more than 200,000 values"),
        ("a: &x [1, *x]\n", "y:1:11: the alias *x refers to a value that contains it"),
        ("[" * 1000, f"y:1:{MAX_DEPTH + 1}: nested more than {MAX_DEPTH} levels deep"),
        ("a: 1\nb: 2\na: 3\n", "y:3:1: duplicate key 'a'"),
        ("t: .nan\n", "y:1:4: '.nan' is not a finite number"),
        ("t: -.inf\n", "y:1:4: '-.inf' is not a finite number"),
        ("t: 1234567890123456\n", "y:1:4: the number 1234567890123456… is too large (more than 15 digits)"),
        ("t: 0x" + "f" * 20 + "\n", "y:1:4: the number 0xffffffffffffffffff… is too large (more than 15 digits)"),
        ("a: !!python/object:os.system x\n", "y:1:4: YAML: could not determine a constructor"),
        ("a: [1\n", "y:2:1: YAML syntax: expected ',' or ']', but got '<stream end>'"),
        ("a: \x01\n", "y:1:4: character #x0001 is not allowed in YAML"),
    ],
)
def test_yaml_that_would_crash_or_hang_a_loader_is_one_positioned_problem(text, message):
    with pytest.raises(BadFile) as caught:
        load_yaml(text, "y")
    assert str(caught.value).startswith(message)


def test_anchors_and_aliases_of_a_normal_size_still_load():
    assert load_yaml("a: &x [1, 2]\nb: *x\nc: {<<: {d: 1}, e: 2}\n", "y") == {
        "a": [1, 2],
        "b": [1, 2],
        "c": {"d": 1, "e": 2},
    }


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('[{"a": 1}, {"a": 2,\n "b": {"a": 0}, "a": 3}]', "j:2:17: duplicate key 'a'"),
        ('{"t": NaN}', "j:1:7: NaN is not a finite number"),
        ('{"t": 1e999}', "j:1:7: 1e999 is not a finite number"),
        ('{"t": -Infinity}', "j:1:7: -Infinity is not a finite number"),
        ('{"t": ' + "7" * 5000 + "}", "j:1:7: the number 77777777777777777777… is too large"),
        ("[" * 100_000, f"j:1:{MAX_DEPTH + 1}: nested more than {MAX_DEPTH} levels deep"),
        ('{"a": [}', "j:1:8: JSON syntax: Expecting value"),
    ],
)
def test_json_that_would_crash_a_loader_is_one_positioned_problem(text, message):
    with pytest.raises(BadFile) as caught:
        load_json(text, "j")
    assert str(caught.value).startswith(message)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"a: 1\nb: \x00\n", ":2:4: a NUL byte: this is not a text file"),
        ("a: 1\nb: é\n".encode("latin-1"), ":2:4: not UTF-8 text (byte 0xe9); save the file as UTF-8"),
        ("a: 1\n".encode("utf-16"), ":1:1: the file is UTF-16 text; save it as UTF-8"),
        (b"x" * 2000, ":1:1: the file is larger than 1 KB; is it the right file?"),
    ],
)
def test_files_that_are_not_small_utf8_text_are_refused(tmp_path, content, message):
    path = tmp_path / "f.yaml"
    path.write_bytes(content)
    with pytest.raises(BadFile) as caught:
        read_text(path, limit=1024)
    assert str(caught.value) == f"{path}{message}"


def test_a_byte_order_mark_is_dropped_and_a_fifo_is_refused_without_waiting(tmp_path):
    (tmp_path / "bom.yaml").write_bytes("\ufeffa: 1\n".encode())
    assert read_text(tmp_path / "bom.yaml") == "a: 1\n"
    os.mkfifo(tmp_path / "fifo")  # nobody writes to it: opening it for reading would wait forever
    with pytest.raises(BadFile, match="fifo:1:1: not a regular file"):
        read_text(tmp_path / "fifo")
