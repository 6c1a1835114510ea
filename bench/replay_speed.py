"""Wall time of replaying every scripted patient end to end (goal: under 2 s for the whole set).

Each script is loaded, run through the real session core and QoS engine on a simulated clock, and
its trace replayed for the statistics -- what `kiosk replay` does. Runs the whole set a few times
and reports the best and median wall time, the simulated time covered, and their ratio.
Optionally (--store) every session is also written to a real SQLite store in a temporary directory.
Prints JSON. Run: uv run python bench/replay_speed.py [--store]
"""

from __future__ import annotations

import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

from kiosk.commands.replay import load_script, run_script
from kiosk.core.questionnaire import load_questionnaire
from kiosk.store.database import Store

ROOT = Path(__file__).resolve().parents[1]
ROUNDS = 5


def one_round(paths: list[Path], questionnaire, store: Store | None) -> tuple[float, float]:
    """(wall seconds, simulated seconds) for the whole set, loading included."""
    began = time.perf_counter()
    simulated = 0.0
    for path in paths:
        result = run_script(load_script(path, questionnaire), questionnaire, store=store)
        simulated += result.simulated_s
    return time.perf_counter() - began, simulated


def main(argv: list[str]) -> int:
    use_store = "--store" in argv
    paths = sorted((ROOT / "recordings/patients").glob("*.yaml"))
    questionnaire = load_questionnaire()
    walls = []
    simulated = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        store = Store.open(tmp) if use_store else None
        for _ in range(ROUNDS):
            wall, simulated = one_round(paths, questionnaire, store)
            walls.append(wall)
        if store is not None:
            store.close()
    best, median = min(walls), statistics.median(walls)
    print(
        json.dumps(
            {
                "scripts": len(paths),
                "rounds": ROUNDS,
                "store": use_store,
                "wall_s_best": round(best, 4),
                "wall_s_median": round(median, 4),
                "simulated_s": round(simulated, 1),
                "speedup_simulated_per_wall": round(simulated / median, 1),
                "wall_per_simulated": round(median / simulated, 7),
                "goal_wall_s": 2.0,
                "goal_met": median < 2.0,
            },
            indent=1,
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
