"""``python -m qos replay TRACE [--json] [--sample-period S] [--plot FILE.png]``."""

import sys

from qos.cli import main, run_command

sys.exit(run_command(main))
