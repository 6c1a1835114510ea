"""Key to screen: the kiosk's screen change against a bare Textual app's, in the same harness
(goal: ratio at most 1.5, issue 32).

Both apps run headless (``run_test``) at the kiosk's size in this process. A key event is posted
the way the terminal driver posts it, and the clock stops once the next screen is on top and has
been drawn once (``call_after_refresh``). The kiosk: a question on screen, P pauses (the paused
screen is pushed over it), P resumes (it is popped and the question shown again). The bare app:
a screen holding a sentence and four buttons, P pushes a screen holding a sentence and a button,
P pops it. Wall and CPU milliseconds (``process_time``) per key are medians over ``--rounds``
pause/resume pairs.

``--instructions`` also counts the instructions of one screen change with valgrind's callgrind:
each app is run under callgrind twice, with N and 2N pause/resume pairs after the same start, and
the difference is divided by 2N keys, so the start cancels out; a figure the machine's load does
not move (on this shared 2-core machine the wall clock moves by a fifth between runs).
Prints JSON. Run: uv run python bench/screen_change.py [--rounds N] [--instructions]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

GOAL_RATIO = 1.5


def bare_app() -> Any:
    """A Textual app with two screens and nothing else: P pushes the second, P pops it."""
    from textual.app import App
    from textual.screen import Screen
    from textual.widgets import Button, Static

    class Question(Screen[None]):
        def compose(self) -> Any:
            yield Static("Do you use the telephone on your own?")
            for n, label in enumerate(("Yes, I look numbers up", "Yes, a few numbers", "I answer it", "No"), 1):
                yield Button(f"{n}  {label}")

    class Paused(Screen[None]):
        def compose(self) -> Any:
            yield Static("Paused. Press P to go on.")
            yield Button("Go on")

    class Bare(App[None]):
        def on_mount(self) -> None:
            self.push_screen(Question())

        def on_key(self, event: Any) -> None:
            if event.key == "p":
                if isinstance(self.screen, Paused):
                    self.pop_screen()
                else:
                    self.push_screen(Paused())

    return Bare()


async def until(condition: Callable[[], object]) -> None:
    """Let the app's event loop run until ``condition()`` holds."""
    for _ in range(100_000):
        if condition():
            return
        await asyncio.sleep(0)
    raise RuntimeError("the app never got there")


async def painted(app: Any) -> None:
    """Wait until the screen has been drawn once more."""
    done = asyncio.Event()
    app.call_after_refresh(done.set)
    await done.wait()


def on_top(app: Any, name: str) -> bool:
    """The screen on top is ``name`` and laid out."""
    screen = app.screen
    return type(screen).__name__ == name and screen.is_mounted and screen.size.area > 0


async def kiosk_to_question(app: Any, clock: Any) -> None:
    """Take a fresh kiosk from the welcome to its first question, as ``bench/ui_session.py`` does."""
    from ui_session import press, to_deadline

    from kiosk.core.session import Phase

    session = app.session
    await until(lambda: on_top(app, "WelcomeScreen"))
    await press(app, "1")
    await until(lambda: session.phase is not Phase.WELCOME)
    while session.phase is Phase.FAMILIARISATION:
        practice = session.snapshot().practice
        if practice is not None and session.current_attempt is not None:
            answered = len(app.controller.events)
            await press(app, str(practice.expected))
            await until(lambda: len(app.controller.events) > answered)
        else:
            to_deadline(app, clock)
    await until(lambda: on_top(app, "ExplanationScreen"))
    await press(app, "1")
    await until(lambda: session.phase is Phase.QUESTIONS)
    to_deadline(app, clock)
    await until(lambda: session.current_attempt == 1 and on_top(app, "QuestionScreen"))
    await painted(app)


async def switches(which: str, pairs: int) -> dict[str, list[tuple[float, float]]]:
    """Run ``which`` ("kiosk" or "bare") to its question, then ``pairs`` pause/resume pairs;
    (wall ms, CPU ms) of each key, by kind."""
    from textual import events

    from kiosk.ui.app import KIOSK_SIZE

    found: dict[str, list[tuple[float, float]]] = {"pause": [], "resume": []}
    with tempfile.TemporaryDirectory() as tmp:
        if which == "kiosk":
            from ui_session import build

            app, clock, store = build(Path(tmp))
            names = ("PausedScreen", "QuestionScreen")
        else:
            app, store, names = bare_app(), None, ("Paused", "Question")
        async with app.run_test(size=KIOSK_SIZE):
            if which == "kiosk":
                await kiosk_to_question(app, clock)
            else:
                await until(lambda: on_top(app, "Question"))
                await painted(app)
            for _ in range(pairs):
                for kind, name in zip(("pause", "resume"), names, strict=True):
                    wall, cpu = time.perf_counter(), time.process_time()
                    app.post_message(events.Key("p", "p"))
                    await until(lambda name=name: on_top(app, name))
                    await painted(app)
                    found[kind].append(((time.perf_counter() - wall) * 1000, (time.process_time() - cpu) * 1000))
        if store is not None:
            store.close()
    return found


def instructions(which: str, pairs: int) -> int:
    """Instructions (valgrind's callgrind) this script runs for ``which`` with ``pairs`` pairs."""
    out = os.path.join(tempfile.mkdtemp(), "callgrind.out")
    subprocess.run(
        ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable, __file__]
        + ["--only", which, "--rounds", str(pairs)],
        check=True,
        capture_output=True,
    )
    with open(out, encoding="utf-8") as f:
        return int(next(line for line in f if line.startswith("totals:")).split()[1])


def per_change(which: str, pairs: int) -> float:
    """Instructions of one screen change: the difference of 2N and N pairs over 2N keys."""
    return (instructions(which, 2 * pairs) - instructions(which, pairs)) / (2 * pairs)


def median(values: list[tuple[float, float]], index: int) -> float:
    return round(statistics.median(v[index] for v in values), 2)


def main(argv: list[str]) -> int:
    """Run both apps and print the JSON figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=15, help="pause/resume pairs per app (default %(default)s)")
    parser.add_argument("--instructions", action="store_true", help="also count instructions under callgrind")
    parser.add_argument("--only", choices=("kiosk", "bare"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.only:  # one app, no figures: what --instructions runs under callgrind
        asyncio.run(switches(args.only, args.rounds))
        return 0
    load_before = os.getloadavg()
    runs = {"bare": asyncio.run(switches("bare", args.rounds)), "kiosk": asyncio.run(switches("kiosk", args.rounds))}
    every = {which: found["pause"] + found["resume"] for which, found in runs.items()}
    result: dict[str, Any] = {
        "pairs": args.rounds,
        "ms_median": {
            which: {kind: {"wall": median(values, 0), "cpu": median(values, 1)} for kind, values in found.items()}
            for which, found in runs.items()
        },
        "wall_ratio": round(
            statistics.median(v[0] for v in every["kiosk"]) / statistics.median(v[0] for v in every["bare"]), 2
        ),
        "cpu_ratio": round(
            statistics.median(v[1] for v in every["kiosk"]) / statistics.median(v[1] for v in every["bare"]), 2
        ),
        "goal_ratio": GOAL_RATIO,
    }
    if args.instructions:
        counted = {which: per_change(which, 4) for which in ("bare", "kiosk")}
        ratio = counted["kiosk"] / counted["bare"]
        result |= {
            "instructions_per_change_M": {which: round(n / 1e6, 2) for which, n in counted.items()},
            "instructions_ratio": round(ratio, 2),
            "instructions_goal_met": ratio <= GOAL_RATIO,
        }
    result["load_average_before_after"] = [round(load_before[0], 2), round(os.getloadavg()[0], 2)]
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
