"""Owner-only files: traces, exports and plots can name a patient, so nobody else may read them."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO


@contextmanager
def open_private(path: str | Path, binary: bool = False) -> Iterator[IO]:
    """Create or replace ``path`` for writing, readable by its owner only (mode 0600).

    ``os.open``'s mode applies only to a file it creates, so an existing file (say 0644) is
    tightened with ``fchmod`` before anything is written into it. Raises ``OSError``.
    """
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    try:
        os.fchmod(descriptor, 0o600)
    except OSError:
        os.close(descriptor)
        raise
    if binary:
        with os.fdopen(descriptor, "wb") as handle:
            yield handle
    else:
        with os.fdopen(descriptor, "w", encoding="utf-8") as handle:
            yield handle


def write_private(path: str | Path, data: str | bytes) -> None:
    """Write text (UTF-8) or bytes to ``path``, created or replaced with mode 0600. Raises ``OSError``."""
    with open_private(path, binary=isinstance(data, bytes)) as handle:
        handle.write(data)


def write_error(path: str | Path, exc: OSError) -> str:
    """The one-line message for a file that cannot be written: ``cannot write PATH: reason``."""
    return f"cannot write {path}: {exc.strerror or exc}"
