"""``kiosk qos …``: the QoS tools from the kiosk command.

``kiosk qos replay …`` is exactly ``python -m qos replay …``; ``kiosk qos trace SESSION`` prints a
stored session's context trace and belongs to the session records (``kiosk.export.opening``), imported
only when asked for.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

from qos.cli import main as qos_main

PROG = "kiosk qos"


def main(argv: Sequence[str] | None = None) -> int:
    """Dispatch ``trace`` to the session records and everything else to the QoS replay tool."""
    args = list(sys.argv[1:] if argv is None else argv)
    if args and args[0] == "trace":
        from kiosk.export.opening import trace_main  # the session store, only when asked for

        return trace_main(args[1:])
    return qos_main(args, prog=PROG, epilog="`kiosk qos trace SESSION` prints a stored session's context trace.")
