"""The clinician PIN: hashed with scrypt, a growing delay and a lockout that survive a restart,
every failure in the security log, and `kiosk pin set` writing the hash into the configuration."""

from __future__ import annotations

import json
import stat
import subprocess
import sys

import pytest

from kiosk.config import ConfigError, load_config
from kiosk.core.pin import (
    FREE_FAILURES,
    LOCKOUT_FAILURES,
    CornerTaps,
    PinError,
    PinGuard,
    hash_pin,
    matches,
)
from kiosk.store.pin_files import LOG_FILE, STATE_FILE, PinFiles


class WallClock:
    """Wall-clock seconds that move only when the test says."""

    def __init__(self) -> None:
        self.t = 1_800_000_000.0

    def __call__(self) -> float:
        return self.t


def test_a_hashed_pin_matches_only_itself_and_hides_the_digits():
    stored = hash_pin("482193")
    assert "482193" not in stored and stored.startswith("scrypt$")
    assert matches(stored, "482193")
    assert not matches(stored, "482194") and not matches(stored, "") and not matches(stored, "4821930")
    assert hash_pin("482193") != stored  # salted


@pytest.mark.parametrize("pin", ["1234", "12345", "1234567890123", "abcdef", "111111", "٤٨٢١٩٣"])
def test_a_new_pin_has_six_to_twelve_digits_and_is_not_trivial(pin):
    with pytest.raises(PinError):
        hash_pin(pin)


def test_failures_grow_the_delay_then_lock_and_a_restart_does_not_reset_them(tmp_path):
    now = WallClock()
    guard = PinGuard(hash_pin("482193"), PinFiles(tmp_path), now=now)
    waits = []
    for _ in range(LOCKOUT_FAILURES):
        if waits and waits[-1] > 0:
            assert guard.attempt("000000").early, "an attempt before the wait is over is not checked"
            now.t += waits[-1]
        verdict = guard.attempt("000000")
        assert not verdict.ok and not verdict.early
        waits.append(verdict.wait_s)
    assert waits[: FREE_FAILURES - 1] == [0.0] * (FREE_FAILURES - 1)
    delays = waits[FREE_FAILURES - 1 :]
    assert delays[0] > 0 and all(b >= a for a, b in zip(delays, delays[1:])) and delays[1] > delays[0]
    assert verdict.locked and waits[-1] >= 3600

    # the kiosk is killed and restarted: the lockout is still there
    restarted = PinGuard(hash_pin("482193"), PinFiles(tmp_path), now=now)
    assert restarted.wait_left() == pytest.approx(waits[-1])
    early = restarted.attempt("482193")
    assert not early.ok and early.early and early.locked, "the right PIN is not even checked while locked"
    now.t += restarted.wait_left()
    assert restarted.attempt("482193").ok
    assert PinGuard(hash_pin("482193"), PinFiles(tmp_path), now=now).failures == 0

    log = [json.loads(line) for line in (tmp_path / LOG_FILE).read_text().splitlines()]
    assert [entry["event"] for entry in log].count("pin_failed") == LOCKOUT_FAILURES
    assert "pin_locked" in [entry["event"] for entry in log] and log[-1]["event"] == "pin_accepted"
    for name in (LOG_FILE, STATE_FILE):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o600


GUESSER = """
import sys
from kiosk.core.pin import PinGuard
from kiosk.store.pin_files import PinFiles
# a kiosk process's PIN pad on the shared data directory; its wall clock stands still, so no wait
# ever runs out and every attempt after the free ones must come back early, unchecked
guard = PinGuard(sys.argv[2], PinFiles(sys.argv[1]), now=lambda: 1_800_000_000.0)
print("ready", guard.failures, flush=True)
sys.stdin.readline()
verdicts = [guard.attempt("000000") for _ in range(int(sys.argv[3]))]
print(sum(not v.early for v in verdicts), flush=True)
"""


@pytest.mark.slow  # a subprocess
def test_two_kiosk_processes_on_one_data_directory_share_one_failure_count(tmp_path):
    secret, tries = hash_pin("482193"), 2 * FREE_FAILURES + 2
    guessers = [
        subprocess.Popen(
            [sys.executable, "-c", GUESSER, str(tmp_path), secret, str(tries)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        for _ in range(2)
    ]
    try:
        # both have read the count (0) before either guesses: a count kept per process stays there
        assert [g.stdout.readline().split() for g in guessers] == [["ready", "0"]] * 2
        for guesser in guessers:  # go, both at once
            guesser.stdin.write("go\n")
            guesser.stdin.flush()
        checked = [int(g.stdout.readline()) for g in guessers]
    finally:
        for guesser in guessers:
            guesser.stdin.close()
            guesser.wait(timeout=60)
    # together they got the free guesses of one kiosk, not one set each (it was 2 x 3)
    assert sum(checked) == FREE_FAILURES, checked
    assert json.loads((tmp_path / STATE_FILE).read_text())["failures"] == FREE_FAILURES
    log = [json.loads(line)["event"] for line in (tmp_path / LOG_FILE).read_text().splitlines()]
    assert log.count("pin_failed") == FREE_FAILURES


def test_a_damaged_failure_count_locks_instead_of_opening(tmp_path):
    (tmp_path / STATE_FILE).write_text('{"failures": "many"')
    guard = PinGuard("482193", PinFiles(tmp_path), now=WallClock())
    assert guard.wait_left() > 0 and not guard.attempt("482193").ok


def test_legacy_plain_pin_still_works_with_a_warning_and_short_ones_are_refused(tmp_path):
    config = tmp_path / "config.yaml"
    config.write_text('clinician_pin: "482193"\n')
    guard = PinGuard(load_config(config, environ={}).pin_secret)
    assert guard.attempt("482193").ok and "kiosk pin set" in guard.warning
    config.write_text('clinician_pin: "2468"\n')
    with pytest.raises(ConfigError, match=r"config\.yaml:1:1: clinician_pin must be 6 to 12 digits"):
        load_config(config, environ={})
    assert "default" in PinGuard(load_config(None, environ={}).pin_secret).warning


@pytest.mark.slow  # a subprocess
def test_kiosk_pin_set_writes_the_hash_owner_only_and_keeps_the_rest(tmp_path):
    config = tmp_path / "config.yaml"
    config.write_text('language: es\n# the ward kiosk\nclinician_pin: "1234"\n')
    config.chmod(0o644)
    done = subprocess.run(
        [sys.executable, "-m", "kiosk", "pin", "set", "--config", str(config)],
        input="482193\n",
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    text = config.read_text()
    assert "482193" not in text and "# the ward kiosk" in text and "clinician_pin:" not in text
    assert stat.S_IMODE(config.stat().st_mode) == 0o600
    loaded = load_config(config, environ={})
    assert loaded.language == "es" and PinGuard(loaded.pin_secret).attempt("482193").ok

    refused = subprocess.run(
        [sys.executable, "-m", "kiosk", "pin", "set", "--config", str(config)],
        input="2468\n",
        capture_output=True,
        text=True,
    )
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1 and "6 to 12 digits" in refused.stderr
    assert config.read_text() == text


def test_five_quick_taps_in_the_corner_and_nowhere_else():
    now = WallClock()
    taps = CornerTaps(now=now)
    assert [taps.tap(1, 1) for _ in range(5)] == [False] * 4 + [True]
    assert [taps.tap(1, 1) for _ in range(4)] + [taps.tap(50, 10)] + [taps.tap(1, 1)] == [False] * 6
    slow = CornerTaps(now=now)
    for _ in range(5):
        now.t += 2.0
        assert not slow.tap(0, 0)
