"""Timed Up and Go from pose landmarks: accuracy of the total per family of generated sequences.

Goals (issue 34): mean absolute error of the total at most 0.2 s on normal sequences and 0.3 s on
noisy or frail ones; no valid result more than 2 s off; negatives refused. Each family's sequences
come from :func:`kiosk.core.tug.families.generate` with seeds ``--seed`` .. ``--seed + --count - 1``
(a person, a pace and a camera drawn per seed), go through the pose-landmarks/1 text (written and
parsed again, as ``kiosk tug analyse`` reads a file) and :func:`kiosk.core.tug.analyse`.

Per positive family: ``mae_s`` (valid results), ``within_0_2`` / ``within_0_3`` (count of valid
results that close), ``worst_s``, ``over_2s`` (valid and more than 2 s off: must be 0),
``invalid_rate`` (positives refused), and ``onset_mae_s`` / ``seated_mae_s``. Per negative family:
``refused_rate``. ``all_positive`` pools the positives. Prints JSON.
Run: uv run python bench/tug.py [--count 40] [--seed 1000] [--families normal,noisy]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

from kiosk.core.tug import analyse, parse_pose_text
from kiosk.core.tug.families import FAMILIES, NEGATIVE, generate
from kiosk.core.tug.landmarks import dump_pose_lines


def _family(family: str, seeds: range) -> dict[str, object]:
    errors, onsets, seats, refused, reasons = [], [], [], 0, {}
    for seed in seeds:
        sequence, truth = generate(family, seed)
        sequence = parse_pose_text("\n".join(dump_pose_lines(sequence)), f"{family}-{seed}")
        result = analyse(sequence)
        if not result.valid:
            refused += 1
            for reason in result.reasons:
                key = reason.split(" (")[0].split(" from t=")[0]
                reasons[key] = reasons.get(key, 0) + 1
            continue
        if truth.total_s is None or result.total_s is None:
            continue
        errors.append(abs(result.total_s - truth.total_s))
        onsets.append(abs((result.onset_t or 0.0) - (truth.onset_t or 0.0)))
        seats.append(abs((result.seated_t or 0.0) - (truth.seated_t or 0.0)))
    count = len(seeds)
    if family in NEGATIVE:
        return {"count": count, "refused_rate": round(refused / count, 3), "reasons": reasons}
    return {
        "count": count,
        "valid": len(errors),
        "mae_s": round(statistics.fmean(errors), 3) if errors else None,
        "within_0_2": sum(e <= 0.2 for e in errors),
        "within_0_3": sum(e <= 0.3 for e in errors),
        "worst_s": round(max(errors), 3) if errors else None,
        "over_2s": sum(e > 2.0 for e in errors),
        "invalid_rate": round(refused / count, 3),
        "onset_mae_s": round(statistics.fmean(onsets), 3) if onsets else None,
        "seated_mae_s": round(statistics.fmean(seats), 3) if seats else None,
        "reasons": reasons,
        "_errors": errors,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=40, help="sequences per family")
    parser.add_argument("--seed", type=int, default=1000, help="the first seed")
    parser.add_argument("--families", default=",".join(FAMILIES), help="comma-separated families")
    args = parser.parse_args()
    began = time.perf_counter()
    seeds = range(args.seed, args.seed + args.count)
    report: dict[str, dict[str, object]] = {}
    pooled: list[float] = []
    for family in args.families.split(","):
        report[family] = _family(family, seeds)
        pooled += report[family].pop("_errors", [])  # type: ignore[arg-type]
    if pooled:
        report["all_positive"] = {
            "valid": len(pooled),
            "mae_s": round(statistics.fmean(pooled), 3),
            "within_0_2": sum(e <= 0.2 for e in pooled),
            "within_0_3": sum(e <= 0.3 for e in pooled),
            "over_2s": sum(e > 2.0 for e in pooled),
        }
    out = {"count_per_family": args.count, "first_seed": args.seed, "seconds": round(time.perf_counter() - began, 1)}
    print(json.dumps(out | {"families": report}, indent=1))


if __name__ == "__main__":
    main()
