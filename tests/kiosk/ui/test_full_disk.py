"""A full disk, as a patient and staff meet it: on a real 2 MB filesystem the kiosk's SQLite store
fills up mid-test. The patient sees one calm out-of-order screen (no notice, nobody's pseudonym,
nothing a tap can start), staff get past the kiosk's own on-disk PIN guard (which counts failures
in memory while it cannot write them) and read the reason, and once space is freed the welcome
comes back and the next test is stored. It needs to mount a tmpfs (root, as in CI's
container); elsewhere it is skipped, saying so."""

from __future__ import annotations

import contextlib
import errno
import os
import subprocess
from pathlib import Path

import pytest

from kiosk.core.pin import FREE_FAILURES, PinGuard
from kiosk.core.session import Phase
from kiosk.store.pin_files import STATE_FILE, PinFiles
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE

from .conftest import UI_PIN, UiKiosk
from .helpers import screen_name, settle, start_in_english, until_drawn

OUT_OF_ORDER = "This kiosk is not working at the moment."


@contextlib.contextmanager
def small_filesystem(folder: Path):
    """A 2 MB tmpfs at ``folder`` (skips where mounting is not allowed)."""
    folder.mkdir()
    done = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=2m,mode=0700", "tmpfs", str(folder)], capture_output=True, text=True
    )
    if done.returncode != 0:
        pytest.skip(f"cannot mount a small filesystem here: {done.stderr.strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", "-l", str(folder)], check=False)


def fill(folder: Path) -> Path:
    """Write a file until the filesystem is full; returns it (delete it to free the space)."""
    filler = folder / "filler"
    handle = os.open(filler, os.O_WRONLY | os.O_CREAT, 0o600)
    try:
        for size in (65536, 4096, 512, 1):  # big blocks, then whatever is left
            with contextlib.suppress(OSError):
                while True:
                    os.write(handle, bytes(size))
    finally:
        os.close(handle)
    return filler


async def _answer_until_out_of_order(kiosk: UiKiosk, pilot) -> None:
    """Go on answering (as the patient would) until a step cannot be stored."""
    for _ in range(len(kiosk.questionnaire.items)):
        if kiosk.controller.out_of_order is not None:
            return
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1 or kiosk.controller.out_of_order is not None)
        if kiosk.controller.out_of_order is None:
            item = kiosk.session.current_item
            await pilot.press("1")
            await settle(pilot, lambda: item.id in kiosk.session.answers or kiosk.controller.out_of_order is not None)
    assert kiosk.controller.out_of_order is not None, "the store never filled up"


async def _the_out_of_order_kiosk_and_its_recovery(kiosk: UiKiosk, pilot, free_space) -> None:
    first = kiosk.session
    shown = await until_drawn(pilot, OUT_OF_ORDER, "Este quiosco no funciona", "Cette borne ne fonctionne pas")
    assert screen_name(kiosk) == "OutOfOrderScreen"
    assert "P-TEST" not in shown and not kiosk.app._notifications  # no notice, no pseudonym
    sessions_before = len(kiosk.store.sessions())
    for key in ("1", "2", "enter", "d"):  # taps and keys start nothing
        await pilot.press(key)
    await pilot.click(offset=(50, 16))
    await settle(pilot)
    assert screen_name(kiosk) == "OutOfOrderScreen" and kiosk.app.session.phase is Phase.WELCOME
    assert len(kiosk.store.sessions()) == sessions_before and not kiosk.app._notifications

    await pilot.press(CLINICIAN_CHORD, *"0000", "enter")  # a slip: counted, though not writable
    await until_drawn(pilot, "Wrong PIN.")
    assert kiosk.app.pin_guard.failures == 1 and not (kiosk.config.data_dir / STATE_FILE).exists()
    await pilot.press(*UI_PIN, "enter")  # staff see why
    await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
    await until_drawn(pilot, "Out of order: the kiosk could not store its last step", "disk is full")
    kiosk.app.close_clinician()
    await settle(pilot, lambda: screen_name(kiosk) == "OutOfOrderScreen")

    kiosk.controller.keep_session()  # the lease timer's round: still full, still out of order
    await settle(pilot)
    assert screen_name(kiosk) == "OutOfOrderScreen"
    free_space()
    kiosk.controller.keep_session()  # space freed: the welcome is back for the next patient
    await until_drawn(pilot, "1  English")
    assert screen_name(kiosk) == "WelcomeScreen" and kiosk.controller.out_of_order is None
    await pilot.press("1")  # the next patient starts, and their test is stored
    await settle(pilot, lambda: kiosk.app.session.phase is not Phase.WELCOME)
    await until_drawn(pilot, "Practice 1 of")
    assert kiosk.store.session(kiosk.app.session.id).status == "running"
    kiosk.controller.keep_session()
    assert first.id in [t.id for t in kiosk.controller.interrupted_tests()]  # the dropped test, for staff


async def test_a_full_filesystem_shows_one_calm_screen_and_recovers_when_space_is_freed(tmp_path):
    with small_filesystem(tmp_path / "small") as small:
        kiosk = UiKiosk(small, familiarisation=False, pin_on_disk=True)
        try:
            async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
                await start_in_english(kiosk, pilot)
                kiosk.to_next_deadline()
                await settle(pilot, lambda: kiosk.session.current_attempt == 1)
                filler = fill(small)
                with pytest.raises(OSError) as full:
                    (small / "one-more").write_bytes(bytes(4096))
                assert full.value.errno == errno.ENOSPC
                await _answer_until_out_of_order(kiosk, pilot)
                assert "full" in kiosk.controller.out_of_order

                def free_space() -> None:
                    filler.unlink()
                    (small / "one-more").unlink(missing_ok=True)

                await _the_out_of_order_kiosk_and_its_recovery(kiosk, pilot, free_space)
        finally:
            kiosk.store.close()


def test_on_a_full_disk_the_pin_lockout_holds_in_memory_and_the_right_pin_gets_in(tmp_path):
    now = [1_800_000_000.0]
    with small_filesystem(tmp_path / "small") as small:
        guard = PinGuard(UI_PIN, PinFiles(small), now=lambda: now[0])  # its lock file is made while there is room
        fill(small)
        verdicts = [guard.attempt("0000") for _ in range(FREE_FAILURES)]
        assert [v.wait_s > 0 for v in verdicts] == [False] * (FREE_FAILURES - 1) + [True]
        assert not (small / STATE_FILE).exists()  # nothing could be written
        early = guard.attempt(UI_PIN)
        assert not early.ok and early.early, "the delay still holds though it is only in memory"
        now[0] += verdicts[-1].wait_s
        assert guard.attempt(UI_PIN).ok


def test_the_ward_station_takes_the_reason_in_the_kiosks_status():
    from station.ward import parse_status

    status = parse_status(
        {"phase": "welcome", "out_of_order": "the kiosk could not store its last step (database or disk is full)"}
    )
    assert status["out_of_order"].endswith("(database or disk is full)")
    assert parse_status({"phase": "welcome"})["out_of_order"] is None
