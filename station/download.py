"""The ``Content-Disposition`` of a download whose name comes from what a kiosk sent.

A session id is any string of up to 64 characters chosen by the kiosk, so it never reaches the
header as it came: the plain ``filename`` keeps only ``A-Z a-z 0-9 . _ -`` (every other run of
characters becomes one ``_``), which needs no quoting in any browser, and ``filename*`` (RFC 6266
/ RFC 8187) carries the same name percent-encoded for clients that prefer it.
"""

from __future__ import annotations

import re
from urllib.parse import quote

_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")
#: longest stem kept (a session id is at most 64 characters; the suffix is added after)
MAX_STEM = 80


def safe_stem(name: str, fallback: str = "session") -> str:
    """``name`` reduced to a safe file-name stem: no quotes, separators, control characters or
    leading dots, at most :data:`MAX_STEM` characters; ``fallback`` when nothing is left."""
    stem = _UNSAFE.sub("_", name).strip("._")[:MAX_STEM]
    return stem or fallback


def attachment(stem: str, suffix: str) -> str:
    """The header value that downloads ``<stem><suffix>`` (the suffix is ours, e.g. ``.csv``)."""
    filename = safe_stem(stem) + suffix
    return f"attachment; filename=\"{filename}\"; filename*=UTF-8''{quote(filename, safe='')}"
