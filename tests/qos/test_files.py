"""Owner-only files: created or replaced with mode 0600, whatever mode an old file had."""

from __future__ import annotations

import stat

import pytest

from qos.files import write_private


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
