"""The RoQME parser's tables are kept between runs in the user's cache directory (only a private
one), and a missing, damaged or foreign cache only means building them again: the same model
parses to the same tree either way."""

from __future__ import annotations

import os
import stat
from importlib import resources

import pytest

from qos import grammar

MODEL = resources.files("qos").joinpath("models", "clarc.roqme").read_text(encoding="utf-8")


@pytest.fixture
def cache_home(tmp_path, monkeypatch):
    """A fresh user cache directory, and a parser built anew against it (and again afterwards)."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    grammar.parser.cache_clear()
    yield tmp_path / "kiosk" / "qos"
    grammar.parser.cache_clear()


def _tree():
    grammar.parser.cache_clear()
    return grammar.parse_text(MODEL)[0]


def test_the_first_parse_keeps_the_tables_in_a_private_directory(cache_home):
    tree = _tree()
    (kept,) = cache_home.glob("*.lark")
    assert stat.S_IMODE(cache_home.stat().st_mode) == 0o700
    assert kept.name.startswith("roqme-") and kept.stat().st_size > 0
    built_at = kept.stat().st_mtime_ns
    assert _tree() == tree  # read back from the cache: the same tree
    assert kept.stat().st_mtime_ns == built_at  # read, not written again
    assert sorted(os.listdir(cache_home)) == sorted([kept.name, kept.with_suffix(".lock").name])


def test_a_damaged_cache_is_built_again(cache_home):
    tree = _tree()
    (kept,) = cache_home.glob("*.lark")
    kept.write_bytes(b"not a parser\n")
    assert _tree() == tree
    assert kept.read_bytes() != b"not a parser\n"


def test_a_cache_directory_others_may_write_is_not_used(cache_home):
    cache_home.mkdir(parents=True)
    cache_home.chmod(0o777)
    assert _tree().data == "start"  # parsed all the same
    assert list(cache_home.iterdir()) == []


def test_a_first_start_takes_the_shipped_tables_without_building_them(cache_home, monkeypatch):
    assert grammar.SHIPPED_TABLES.read_bytes().split(b"\n", 1)[0].decode() == grammar._tables_key(), (
        "the grammar, lark or Python changed: run grammar.write_shipped_tables()"
    )
    tree_from_shipped = _tree()
    (kept,) = cache_home.glob("*.lark")
    copied = kept.read_bytes()
    assert copied.endswith(grammar.SHIPPED_TABLES.read_bytes().split(b"\n", 1)[1])  # lark did not rebuild it
    monkeypatch.setattr(grammar, "SHIPPED_TABLES", cache_home / "none.lark")  # nothing shipped: built
    kept.unlink()
    assert _tree() == tree_from_shipped
    assert kept.read_bytes() != copied  # built by lark: its own key and grammar files head it
