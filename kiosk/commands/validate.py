"""`kiosk validate [FILE...] [--words [DIR]]`: list every problem of questionnaire files and of the
kiosk's words files, one per line as ``file:line:col: problem``.

Exit status 0 when everything is valid, 1 when anything has a problem, 2 when a file cannot be read
as YAML at all (missing, not UTF-8, binary, too big or deep, a syntax error) or on bad usage. The
same checks run when the kiosk loads a questionnaire and its words, so what this command accepts
the kiosk starts with. Questionnaires are checked with the kiosk's own words files; ``--words DIR``
checks another directory of them (a translation in progress) and lists its languages.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from kiosk.core.questionnaire import check_questionnaire
from kiosk.core.words import WORDS_DIR, check_words


def main(argv: list[str]) -> int:
    """Validate questionnaire files and words files; returns the exit status."""
    parser = argparse.ArgumentParser(
        prog="kiosk validate",
        description="List every problem of questionnaire files and of the words files (one per language), "
        "one per line as file:line:col: problem; exit 1 if any, 2 if a file cannot be read as YAML.",
    )
    parser.add_argument("files", nargs="*", metavar="FILE", help="questionnaire YAML file(s)")
    parser.add_argument(
        "--words",
        nargs="?",
        const=str(WORDS_DIR),
        metavar="DIR",
        help=f"a directory of words files, <language>.yaml (default: the kiosk's own, {WORDS_DIR}); "
        "its languages are listed",
    )
    args = parser.parse_args(argv)
    if not args.files and args.words is None:
        parser.error("give questionnaire FILEs, --words [DIR], or both")
    status = _words(Path(args.words or WORDS_DIR), listed=args.words is not None)
    for file in args.files:
        readable, problems = check_questionnaire(file)
        for problem in problems:
            print(problem)
        if not readable:
            status = 2
        elif problems:
            status = max(status, 1)
        else:
            print(f"{file}: ok", file=sys.stderr)
    return status


def _words(directory: Path, listed: bool) -> int:
    """Check a directory of words files; print its problems, and its languages when ``listed``."""
    if not directory.is_dir():
        print(f"{directory}: not a directory of words files")
        return 2
    words, problems, readable = check_words(directory)
    for problem in problems:
        print(problem)
    if listed and not problems:
        print(f"{directory}: ok, languages {', '.join(words)}", file=sys.stderr)
    return 2 if not readable else 1 if problems else 0
