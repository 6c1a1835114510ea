"""`kiosk tug`: the Timed Up and Go from pose-landmarks files, without a camera.

``kiosk tug analyse FILE... [--json]`` reads each pose-landmarks/1 file (docs/tug.md) and prints
its analysis: with ``--json`` one JSON object per file, one per line (JSON Lines, in the order
given), else a few readable lines per file. Exit status 0 when every file was analysed, valid or
not; 2 when a file cannot be read (one line on stderr naming the file and line; the other files are
still analysed). ``kiosk tug generate FAMILY [--seed N] [-o FILE]`` writes a synthetic sequence
with known times (its truth on stderr), for trying the analysis and the replay.
"""

from __future__ import annotations

import argparse
import json
import sys

from fileio.bounded import BadFile, read_text
from kiosk.core.tug import PoseFileError, TugAnalysis, analyse, parse_pose_text

#: the largest file read: a minute at 60 fps is about 5 MB
MAX_FILE_BYTES = 64 * 1024 * 1024


def main(argv: list[str]) -> int:
    """Run ``kiosk tug``; returns the exit status."""
    parser = argparse.ArgumentParser(prog="kiosk tug", description="Timed Up and Go from pose-landmarks files.")
    commands = parser.add_subparsers(dest="command", required=True)
    analyse_parser = commands.add_parser("analyse", help="analyse pose-landmarks/1 files")
    analyse_parser.add_argument("files", nargs="+", metavar="FILE")
    analyse_parser.add_argument("--json", action="store_true", help="one JSON object per file, one per line")
    generate_parser = commands.add_parser("generate", help="write a synthetic sequence with known times")
    generate_parser.add_argument("family", help="normal, frail, hesitant, fps15, fps60, noisy, mirrored, ...")
    generate_parser.add_argument("--seed", type=int, default=0)
    generate_parser.add_argument("-o", "--output", metavar="FILE", help="where to write (default: stdout)")
    args = parser.parse_args(argv)
    if args.command == "generate":
        return _generate(args.family, args.seed, args.output)
    status = 0
    for path in args.files:
        try:
            sequence = parse_pose_text(read_text(path, MAX_FILE_BYTES), path)
        except BadFile as error:
            print(f"kiosk tug analyse: {error.problem}", file=sys.stderr)
            status = 2
            continue
        except PoseFileError as error:
            print(f"kiosk tug analyse: {error}", file=sys.stderr)
            status = 2
            continue
        result = analyse(sequence)
        if args.json:
            print(json.dumps({"file": path} | result.as_json()), flush=True)
        else:
            print(describe(path, result), flush=True)
    return status


def describe(path: str, result: TugAnalysis) -> str:
    """A few readable lines about one file's result."""
    if not result.valid or result.total_s is None:
        return f"{path}: not valid\n" + "".join(f"  - {reason}\n" for reason in result.reasons)
    start = (
        f"Go at t={result.go_t:.2f} s" if result.go_t is not None else f"the first movement at t={result.onset_t:.2f} s"
    )
    lines = [f"{path}: {result.total_s:.2f} s, from {start} to seated at t={result.seated_t:.2f} s"]
    for phase in result.phases:
        name = phase.name.replace("_", " ")
        lines.append(f"  {name:<13} {phase.start_t:7.2f} - {phase.end_t:7.2f} s  ({phase.duration_s:.2f} s)")
    q = result.quality
    turn = "turn seen" if q.get("turn_seen") else "no turn seen"
    lines.append(f"  a person in {q['person_share']:.0%} of the frames, the legs in {q['legs_share']:.0%}; {turn}")
    return "\n".join(lines) + "\n"


def _generate(family: str, seed: int, output: str | None) -> int:
    from fileio.bounded import write_error, write_private
    from kiosk.core.tug.families import FAMILIES, generate
    from kiosk.core.tug.landmarks import dump_pose_lines

    if family not in FAMILIES:
        print(f"kiosk tug generate: unknown family {family!r}; one of {', '.join(FAMILIES)}", file=sys.stderr)
        return 2
    sequence, truth = generate(family, seed)
    text = "\n".join(dump_pose_lines(sequence)) + "\n"
    total = "none (a negative)" if truth.total_s is None else f"{truth.total_s:.3f} s"
    print(f"kiosk tug generate: {family} seed {seed}, {truth.view} view, true total {total}", file=sys.stderr)
    if output is None:
        sys.stdout.write(text)
        return 0
    try:
        write_private(output, text)
    except OSError as error:
        print(f"kiosk tug generate: {write_error(output, error)}", file=sys.stderr)
        return 2
    return 0
