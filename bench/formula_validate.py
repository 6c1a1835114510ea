"""`kiosk validate` on hostile total formulas (goal: each under 5 s, none hangs or crashes).

Writes one instrument per hostile shape (the issue 35 corpus: a regex reached in a mixed answer,
a 60^4 product, repeat(), a huge max, a 20,000-term sum, deep nesting, today(), an odd sum
halved, a misspelled id in iif, trace(); and formulas the range reasoning cannot prove, so every
combination of answers is tried: four items of six options (proved), six (past the budget)), runs
``kiosk validate`` on it in a fresh process, and prints JSON: the wall seconds, the exit status
and the first line printed, per shape.
Run: uv run python bench/formula_validate.py
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.kiosk.core.instruments_v2 import bands, choice, instrument  # noqa: E402

A = "%resource.item.where(linkId = '{}').answer.value"


def weights(*ids: str) -> str:
    return " + ".join(f"{A.format(i)}.weight()" for i in ids)


def file(formula: str, items: list[str], low: int = 0, high: int = 100, options: int = 3) -> str:
    body = "".join(choice(i, list(range(options))) for i in items)
    scoring = f'scoring:\n  total:\n    fhirpath: "{formula}"\n    min: {low}\n    max: {high}\n'
    return instrument("hostile", body, bands(("all", low, high)), scoring)


TWO = ["a", "b"]
SIXTY = [f"i{n}" for n in range(60)]
SIX = [f"s{n}" for n in range(6)]
NESTED = "%resource.item.where(%resource.item.where(%resource.item.where(%resource.item.exists()).exists()).exists())"
SHAPES = {
    "regex_in_mixed_answer": file(
        f"iif({A.format('a')}.weight() = 1 and {A.format('b')}.code.matches('(x+x+)+y'), 1, 0)", TWO
    ),
    "product_60_4": file(f"{NESTED}.count()", SIXTY, high=60, options=2),
    "repeat": file("%resource.repeat(item).count()", TWO),
    "huge_max": file(weights("a", "b"), TWO, high=999_999_999_999),
    "sum_20000_terms": file(" + ".join(["1"] * 20_000), TWO),
    "deep_nesting": file("(" * 5_000 + "1" + ")" * 5_000, TWO),
    "today": file(f"{weights('a')} + today().count()", TWO),
    "odd_sum_halved": file(f"({weights('a', 'b')}) / 2", TWO),
    "misspelled_in_iif": file(f"iif({A.format('bb')}.weight() > 0, 1, 0)", TWO),
    "trace": file(f"{weights('a')}.trace('x')", TWO),
    "every_combination_4x6_proved": file(f"(({weights(*SIX[:4])}) * 2) / 2", SIX[:4], high=100, options=6),
    "every_combination_6x6": file(f"(({weights(*SIX)}) * 2) / 2", SIX, high=100, options=6),
}


def main() -> None:
    results = {}
    with tempfile.TemporaryDirectory() as folder:
        for name, text in SHAPES.items():
            path = Path(folder) / f"{name}.yaml"
            path.write_text(text, encoding="utf-8")
            start = time.perf_counter()
            done = subprocess.run(
                [sys.executable, "-m", "kiosk", "validate", str(path)], capture_output=True, text=True, cwd=ROOT
            )
            seconds = time.perf_counter() - start
            first = (done.stdout.splitlines() or done.stderr.splitlines() or [""])[0]
            results[name] = {
                "seconds": round(seconds, 2),
                "status": done.returncode,
                "traceback": "Traceback" in done.stderr,
                "first_line": first.split(": ", 1)[-1][:160],
            }
    slowest = max(r["seconds"] for r in results.values())
    print(json.dumps({"shapes": results, "slowest_s": slowest, "goal_s": 5.0, "met": slowest < 5.0}, indent=2))


if __name__ == "__main__":
    main()
