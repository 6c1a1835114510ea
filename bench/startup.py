"""Start-up: launch to the welcome, the kiosk against a two-widget Textual app started the same way
(goal: ratio at most 1.5).

Both run as ``python -m …`` (same interpreter, same environment, bytecode written and kept as on
an installed kiosk) on a pseudo-terminal of 100x32, fresh data directory, no station; the clock
stops when the welcome's "English" button is on the terminal (escape sequences stripped), which is
what a patient waits for. One warm-up launch of each is not counted (it writes the bytecode and the
QoS grammar's cache, as a kiosk's first start after installing does). Rounds alternate the two apps
so machine load hits both alike; the medians' ratio is the figure. The CPU seconds each process used
to the welcome (its rusage when killed there) are reported too: they move less with machine load
than the wall clock. ``kiosk_phases`` splits the kiosk's start (imports, build_app, the first frame
drawn headless) in one process, to show where the time goes. Also reports ``python -X importtime``
of ``kiosk.ui.app``'s heaviest imports and the load average before and after. ``--instructions``
also counts the instructions each app runs to its welcome under valgrind's callgrind (same
pseudo-terminal; about two minutes): a figure the machine's load does not move, unlike the others
(on a 2-core machine their medians move by a fifth between runs). Prints JSON.

``--first-start`` empties the kiosk's kept caches (``<user cache dir>/kiosk``: the QoS grammar's
tables, kept QoS models, questionnaires, words and parsed YAML, documents that passed a schema)
before every counted kiosk launch, as the first start after an install or upgrade finds them (the
bytecode is kept: an installer writes it); goal: ratio at most 1.8. ``--ward`` gives the kiosk the
configuration a ward kiosk ships, a ``station:`` section (url on 127.0.0.1 at a closed port, token,
kiosk id); goal: ratio at most 1.5. The cache is a folder of the bench's own (``XDG_CACHE_HOME``).
Run: uv run python bench/startup.py [--rounds N] [--instructions] [--first-start] [--ward]
"""

from __future__ import annotations

import argparse
import fcntl
import json
import os
import pty
import re
import select
import shutil
import signal
import statistics
import struct
import subprocess
import sys
import tempfile
import termios
import time

#: the baseline: two widgets, the same first words a patient sees
TWO_WIDGET_APP = """
from textual.app import App
from textual.widgets import Button, Static

class TwoWidgets(App):
    def compose(self):
        yield Static("Welcome. Please choose your language.")
        yield Button("1  English")

TwoWidgets().run()
"""
MARKER = b"English"
_ANSI = re.compile(rb"\x1b\[[0-9;?<>=]*[A-Za-z~]|\x1b[()][A-Z0-9]|\x1b\][^\x07\x1b]*(\x07|\x1b\\)|\x1b[=>]")


#: a ward kiosk's configuration: its station at a port nothing listens on (PORT filled in)
WARD_CONFIG = 'station: {url: "http://127.0.0.1:PORT", token: "bench-token-0123456789abcdef", kiosk_id: bench-bed1}\n'


def closed_port() -> int:
    """A port on 127.0.0.1 nothing listens on (bound, then released)."""
    import socket

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def empty_caches(env: dict[str, str]) -> None:
    """Remove the kiosk's kept caches, as an install or an upgrade leaves them."""
    shutil.rmtree(os.path.join(env["XDG_CACHE_HOME"], "kiosk"), ignore_errors=True)


def time_to_marker(argv: list[str], env: dict[str, str], timeout_s: float = 60.0) -> tuple[float, float]:
    """(wall seconds from fork to MARKER drawn on a 100x32 pseudo-terminal, CPU seconds the process
    used until then); the process is killed as soon as MARKER is seen."""
    began = time.perf_counter()
    pid, fd = pty.fork()
    if pid == 0:  # pragma: no cover - the child
        os.execvpe(argv[0], argv, env)
    fcntl.ioctl(fd, termios.TIOCSWINSZ, struct.pack("HHHH", 32, 100, 0, 0))
    seen = b""
    try:
        while MARKER not in _ANSI.sub(b"", seen):
            ready, _, _ = select.select([fd], [], [], max(0.0, began + timeout_s - time.perf_counter()))
            if not ready:
                raise TimeoutError(f"{argv[-1]} drew no {MARKER!r} within {timeout_s} s")
            try:
                seen += os.read(fd, 65536)
            except OSError:  # the child closed the terminal: it exited before the welcome
                raise RuntimeError(
                    f"{argv[-1]} exited before the welcome: {_ANSI.sub(b'', seen)[-400:].decode(errors='replace')}"
                ) from None
        wall = time.perf_counter() - began
    finally:
        os.kill(pid, signal.SIGKILL)
        _, _, usage = os.wait4(pid, 0)
        os.close(fd)
    return wall, usage.ru_utime + usage.ru_stime


#: where the kiosk's start goes, in one process: imports, `kiosk run`'s build_app (configuration,
#: questionnaire, QoS model, store, channels), and the app run headless until the welcome is drawn
PHASES = """
import asyncio, json, sys, time
marks = [(time.perf_counter(), time.process_time())]
import kiosk.cli, qos.cli
from kiosk.commands.run import build_app
from kiosk.ui.app import KIOSK_SIZE
marks.append((time.perf_counter(), time.process_time()))
app, close = build_app()
marks.append((time.perf_counter(), time.process_time()))
async def welcome():
    async with app.run_test(size=KIOSK_SIZE) as pilot:
        while not (type(app.screen).__name__ == "WelcomeScreen" and app.screen.query("Button")):
            await pilot.pause()
        marks.append((time.perf_counter(), time.process_time()))
asyncio.run(welcome())
close()
names = ("import", "build_app", "first_frame_headless")
print(json.dumps({n: [b[0] - a[0], b[1] - a[1]] for n, a, b in zip(names, marks, marks[1:])}))
"""


#: runs ``python -m MODULE`` (argv[1]) as it is, exiting (status 0) after the first display that shows a
#: button labelled "English": Textual's App.post_display_hook is set the moment textual.app is
#: imported, so neither app imports anything earlier or in another order than it would alone
TO_THE_WELCOME = """
import importlib.abc, importlib.machinery, os, runpy, sys

def shown(app):
    from textual.widgets import Button
    try:
        if any("English" in str(button.label) for button in app.screen.query(Button)):
            os._exit(0)
    except Exception:  # no screen yet
        pass

class Hook(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name != "textual.app":
            return None
        sys.meta_path.remove(self)
        spec = importlib.machinery.PathFinder.find_spec(name, path)
        run = spec.loader.exec_module
        def exec_module(module):
            run(module)
            module.App.post_display_hook = shown
        spec.loader.exec_module = exec_module
        return spec

sys.meta_path.insert(0, Hook())
runpy.run_module(sys.argv.pop(1), run_name="__main__", alter_sys=True)  # argv as `python -m` gives it
"""


def instructions(env: dict[str, str], module: str) -> int:
    """Instructions (valgrind's callgrind) ``python -m module`` runs from launch to its welcome on a
    100x32 pseudo-terminal: a count the machine's load does not move."""
    out = os.path.join(tempfile.mkdtemp(), "callgrind.out")
    pid, fd = pty.fork()
    if pid == 0:  # pragma: no cover - the child
        argv = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable, "-c", TO_THE_WELCOME]
        os.execvpe("valgrind", [*argv, module], env)
    fcntl.ioctl(fd, termios.TIOCSWINSZ, struct.pack("HHHH", 32, 100, 0, 0))
    while True:  # the terminal must be read, or the app blocks writing to it
        try:
            if not os.read(fd, 65536):
                break
        except OSError:
            break
    _, status = os.waitpid(pid, 0)
    os.close(fd)
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{module} under callgrind exited with {os.waitstatus_to_exitcode(status)}")
    with open(out, encoding="utf-8") as f:
        totals = [line for line in f if line.startswith("totals:")]
    return int(totals[0].split()[1])


def phases(env: dict[str, str], rounds: int, first_start: bool) -> dict[str, dict[str, float]]:
    """Median wall and CPU seconds of each phase of PHASES over ``rounds`` fresh processes (CPU
    counts every thread: the channels start theirs when the app mounts)."""
    runs = []
    for _ in range(rounds):
        if first_start:
            empty_caches(env)
        done = subprocess.run([sys.executable, "-c", PHASES], env=env, capture_output=True, text=True, check=True)
        runs.append(json.loads(done.stdout))
    return {
        name: {
            "wall_s": round(statistics.median(run[name][0] for run in runs), 3),
            "cpu_s": round(statistics.median(run[name][1] for run in runs), 3),
        }
        for name in runs[0]
    }


def heaviest_imports(n: int = 8) -> list[dict[str, object]]:
    """The ``n`` largest cumulative import times (ms) under ``import kiosk.ui.app``."""
    err = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", "import kiosk.ui.app"], capture_output=True, text=True, check=True
    ).stderr
    rows: list[tuple[float, str]] = []
    for line in err.splitlines():
        parts = line.split("|")
        if len(parts) == 3 and parts[1].strip().isdigit():
            rows.append((int(parts[1]) / 1000, parts[2].strip()))
    return [{"module": module, "cumulative_ms": ms} for ms, module in sorted(rows, reverse=True)[:n]]


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument(
        "--instructions",
        action="store_true",
        help="also count instructions to the welcome with valgrind (about two minutes; needs valgrind)",
    )
    parser.add_argument("--first-start", action="store_true", help="empty the kept caches before each kiosk launch")
    parser.add_argument("--ward", action="store_true", help="a configuration with a station: section")
    args = parser.parse_args(argv)
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        baseline = os.path.join(tmp, "two_widgets.py")
        with open(baseline, "w", encoding="utf-8") as f:
            f.write(TWO_WIDGET_APP)
        config = os.path.join(tmp, "config.yaml")
        with open(config, "w", encoding="utf-8") as f:
            f.write(WARD_CONFIG.replace("PORT", str(closed_port())) if args.ward else "{}\n")
        env = dict(
            os.environ,
            TERM="xterm-256color",
            KIOSK_DATA_DIR=os.path.join(tmp, "data"),
            KIOSK_CONFIG=config,
            XDG_CACHE_HOME=os.path.join(tmp, "cache"),
        )
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [tmp, env.get("PYTHONPATH")]))
        env.pop("KIOSK_STATION_URL", None)
        env.pop("PYTHONDONTWRITEBYTECODE", None)  # an installed kiosk has its bytecode; so has Textual
        apps = {"two_widget": [sys.executable, "-m", "two_widgets"], "kiosk": [sys.executable, "-m", "kiosk"]}
        for command in apps.values():  # the warm-up, not counted
            time_to_marker(command, env)
        runs: dict[str, list[tuple[float, float]]] = {name: [] for name in apps}
        for _ in range(args.rounds):
            for name, command in apps.items():
                if name == "kiosk" and args.first_start:
                    empty_caches(env)
                runs[name].append(time_to_marker(command, env))
        kiosk_phases = phases(env, max(3, args.rounds // 2), args.first_start)
        counted = None
        if args.instructions:
            counted = {"two_widget": instructions(env, "two_widgets")}
            if args.first_start:
                empty_caches(env)
            counted["kiosk"] = instructions(env, "kiosk")
    wall = {name: [w for w, _ in found] for name, found in runs.items()}
    cpu = {name: [c for _, c in found] for name, found in runs.items()}
    two, kiosk = wall["two_widget"], wall["kiosk"]
    ratio = statistics.median(kiosk) / statistics.median(two)
    goal = 1.8 if args.first_start else 1.5
    cpu_ratio = statistics.median(cpu["kiosk"]) / statistics.median(cpu["two_widget"])
    print(
        json.dumps(
            {
                "rounds": args.rounds,
                "mode": {"first_start": args.first_start, "ward": args.ward},
                "two_widget_s_median": round(statistics.median(two), 3),
                "kiosk_s_median": round(statistics.median(kiosk), 3),
                "kiosk_s_best": round(min(kiosk), 3),
                "ratio_median": round(ratio, 2),
                "goal_ratio": goal,
                "goal_met": ratio <= goal,
                "two_widget_cpu_s_median": round(statistics.median(cpu["two_widget"]), 3),
                "kiosk_cpu_s_median": round(statistics.median(cpu["kiosk"]), 3),
                "cpu_ratio_median": round(cpu_ratio, 2),
                "kiosk_phases": kiosk_phases,
                **(
                    {
                        "instructions_M": {name: round(n / 1e6) for name, n in counted.items()},
                        "instructions_ratio": round(counted["kiosk"] / counted["two_widget"], 2),
                        "instructions_goal_met": counted["kiosk"] / counted["two_widget"] <= goal,
                    }
                    if counted
                    else {}
                ),
                "load_average_before_after": [round(load_before[0], 2), round(os.getloadavg()[0], 2)],
                "heaviest_imports_ms": heaviest_imports(),
            },
            indent=2,
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
