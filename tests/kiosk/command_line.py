"""The `kiosk` command lines as a user starts them, for the tests of what they refuse: a real
process with a clean environment, and the one ``file:line:col`` line a bad input must give."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: a guard against a hang, not a timing assertion: the reader's caps are what bound the work
HANG_S = 120


def kiosk(*args: str, cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    """A real `kiosk` process in ``cwd``, which is its home too (no user configuration), with a clean
    environment and ``env``."""
    return subprocess.run(
        [sys.executable, "-m", "kiosk", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=HANG_S,
        check=False,
        env={"PATH": "/usr/bin:/bin", "HOME": str(cwd), **(env or {})},
    )


def kiosk_run(config: Path, cwd: Path, *options: str) -> subprocess.CompletedProcess:
    """`kiosk run` with ``config``, its data in ``cwd``/data, no voice and ``options``."""
    return kiosk("run", "--config", str(config), "--data-dir", str(cwd / "data"), "--no-voice", *options, cwd=cwd)


def one_line(done: subprocess.CompletedProcess, where: str, stream: str = "stderr") -> str:
    """The one line ``done`` wrote on ``stream``, which holds ``where``, after exit status 2 and
    no traceback."""
    text = getattr(done, stream)
    assert done.returncode == 2, (done.returncode, done.stderr, done.stdout)
    assert "Traceback" not in done.stderr and text.count("\n") == 1, text
    assert where in text, text
    return text


def write(folder: Path, name: str, content: str | bytes) -> Path:
    """``content`` as the file ``name`` in ``folder`` (text as UTF-8)."""
    path = folder / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    return path
