"""Times as ward staff read them: in the site's time zone, never in UTC.

The station stores every time as ISO-8601 UTC; pages, prints and the handover show them in the
zone the station is started with (``kiosk station serve --time-zone Europe/Madrid``; default the
machine's own zone), with the zone's abbreviation, so a nurse in Seville reads 10:15 CET for a
visit stored as 09:15Z. Templates use the ``when`` filter; code uses :func:`shown`.
"""

from __future__ import annotations

from datetime import datetime, tzinfo
from typing import Any

#: what each form of the ``when`` filter shows
FORMS = {"minute": "%Y-%m-%d %H:%M %Z", "second": "%Y-%m-%d %H:%M:%S %Z", "time": "%H:%M:%S %Z", "date": "%Y-%m-%d"}


class ZoneError(ValueError):
    """A time zone the station does not know (the message names it)."""


def zone_named(name: str | None) -> tzinfo | None:
    """The IANA zone ``name`` (None or "": the machine's own zone, returned as None)."""
    if not name:
        return None
    from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

    try:
        return ZoneInfo(name)
    except (ZoneInfoNotFoundError, ValueError):
        raise ZoneError(
            f"--time-zone {name[:60]!r}: not a time zone this machine knows (an IANA name, such as Europe/Madrid)"
        ) from None


def shown(iso: Any, zone: tzinfo | None = None, form: str = "minute") -> str:
    """``iso`` (an ISO-8601 text; naive ones are UTC, as the station stores them) in ``zone``
    (None: the machine's zone) as ``FORMS[form]``; "" for none, the text itself if unreadable."""
    if not iso:
        return ""
    try:
        when = datetime.fromisoformat(str(iso).replace("Z", "+00:00"))
    except ValueError:
        return str(iso)
    if when.tzinfo is None:
        from datetime import UTC

        when = when.replace(tzinfo=UTC)
    return when.astimezone(zone).strftime(FORMS[form]).strip()
