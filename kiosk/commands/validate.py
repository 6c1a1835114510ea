"""`kiosk validate FILE...`: list every problem of a questionnaire file as ``file:line:col: problem``.

Exit status 0 when every file is valid, 1 when any has a problem, 2 when one cannot be read as YAML
at all (missing, not UTF-8, binary, too big or deep, a syntax error) or on bad usage. The same checks
run when the kiosk loads a questionnaire, so a file this command accepts is one the kiosk starts with.
"""

from __future__ import annotations

import argparse
import sys

from kiosk.core.questionnaire import check_questionnaire


def main(argv: list[str]) -> int:
    """Validate questionnaire files; returns the exit status."""
    parser = argparse.ArgumentParser(
        prog="kiosk validate",
        description="List every problem of questionnaire files, one per line as file:line:col: problem; "
        "exit 1 if any, 2 if a file cannot be read as YAML.",
    )
    parser.add_argument("files", nargs="+", metavar="FILE", help="questionnaire YAML file(s)")
    args = parser.parse_args(argv)
    status = 0
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
