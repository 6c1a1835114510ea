"""A real kiosk process for the multi-kiosk tests: `kiosk run`'s own build_app on a data directory,
driven headless through Textual's Pilot by commands read from stdin, one JSON line out per command.

    python tests/kiosk/ui/kiosk_process.py CONFIG

Commands: ``start`` (touch "Start in English", unless continuing, and the explanation's Start), ``answer N`` (wait for
the next question, answer option N), ``state``, ``clinician`` (the chord and the PIN; lists the
interrupted tests), ``continue`` (touch "Continue this test" on the first), ``back`` (leave the
clinician screens), ``quit``. Every reply carries the state: session id, phase, answers, screen,
and the notices the kiosk showed.
"""

from __future__ import annotations

import asyncio
import json
import sys
import time
from pathlib import Path

from kiosk.commands.run import build_app
from kiosk.core.session import Phase
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE

#: how long a command may wait for the kiosk (real timers, real threads)
PATIENCE_S = 30.0


async def main(config: Path, pin: str) -> None:
    app, close = build_app(config_path=config, voice=False, remote=False)
    notices: list[str] = []
    notify = app.notify

    def noting(message: str, **kwargs) -> None:  # what the screen showed, for the test to read
        notices.append(message)
        notify(message, **kwargs)

    app.notify = noting  # type: ignore[method-assign]  # the notices the kiosk showed, for the test
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:

            async def until(condition) -> bool:
                deadline = time.monotonic() + PATIENCE_S
                while time.monotonic() < deadline:
                    await pilot.pause()
                    if condition():
                        return True
                    await asyncio.sleep(0.02)  # bounded wait on the kiosk's own timers
                return False

            def state(**extra) -> dict:
                session = app.session
                return {
                    "session": session.id,
                    "patient": session.patient_id,
                    "phase": session.phase.value,
                    "answers": sorted(session.answers),
                    "screen": type(app.screen).__name__,
                    "notices": notices,
                    **extra,
                }

            loop = asyncio.get_running_loop()
            print(json.dumps(state(ready=True)), flush=True)
            while True:
                line = (await loop.run_in_executor(None, sys.stdin.readline)).split()
                if not line or line[0] == "quit":
                    break
                command, extra = line[0], {}
                if command == "start":
                    if app.session.phase is Phase.WELCOME:
                        await pilot.press("1")
                    await until(lambda: app.session.phase is Phase.EXPLANATION)
                    await pilot.press("1")
                    extra["ok"] = await until(lambda: app.session.phase is Phase.QUESTIONS)
                elif command == "answer":
                    session = app.session
                    extra["ok"] = await until(lambda: session.current_attempt is not None or app.session is not session)
                    if app.session is session and extra["ok"]:
                        item = session.current_item.id
                        await pilot.press(line[1])
                        extra["ok"] = await until(lambda: item in session.answers or app.session is not session)
                        extra["item"] = item
                elif command == "clinician":
                    await pilot.press(CLINICIAN_CHORD, *pin, "enter")
                    extra["ok"] = await until(lambda: type(app.screen).__name__ == "ClinicianHomeScreen")
                    table = app.screen.query_one("#interrupted")
                    extra["interrupted"] = [list(map(str, table.get_row_at(i))) for i in range(table.row_count)]
                elif command == "continue":
                    await pilot.click("#continue-test")
                    await pilot.pause()
                    if type(app.screen).__name__ == "ClinicianHomeScreen":
                        extra["refused"] = str(app.screen.query_one("#continue-result").render())
                elif command == "back":
                    app.close_clinician()
                    await pilot.pause()
                print(json.dumps(state(**extra)), flush=True)
    finally:
        close()


if __name__ == "__main__":
    asyncio.run(main(Path(sys.argv[1]), sys.argv[2]))
