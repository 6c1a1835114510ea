"""The kiosk's side of the ward station (``docs/station-protocol.md``): a background client that
delivers the outbox, reports live status and fetches staff commands.

Nothing here touches the session or the screens: commands are handed to a callback that the app
runs on its own thread (``app.call_from_thread``). Without a station configured nothing of this
package is started. The package itself imports nothing of the client (``http.client``, threads):
the UI reads the session's live status (:mod:`kiosk.sync.commands`) before the welcome is drawn,
and the client is built after it (:mod:`kiosk.ui.compose`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from kiosk.sync.client import SyncClient
    from kiosk.sync.outbox import Outbox

__all__ = ["Outbox", "SyncClient", "deliver_pending"]

#: how long a command that exits (``kiosk replay``) tries to hand its outbox to the station
EXIT_DELIVERY_S = 30.0


def deliver_pending(db_path: Path, station: Any, within_s: float = EXIT_DELIVERY_S) -> str | None:
    """Deliver the outbox of ``db_path`` to ``station`` (a ``kiosk.config.Station``), trying for at
    most ``within_s`` seconds. None once everything is delivered, else one sentence for the user:
    what is left, why, and that it is kept for the next kiosk on this data directory."""
    from kiosk.sync.client import SyncClient

    client = SyncClient(db_path, url=station.url, token=station.token, kiosk_id=station.kiosk_id)
    try:
        left = client.deliver_all(within_s)
    finally:
        client.stop()
    if not left:
        return None
    return (
        f"the station at {station.url} did not take {left} stored change{'s' if left != 1 else ''} "
        f"within {within_s:g} s ({client.problem or 'no reason given'}); they are kept in {db_path} and go "
        "with the next `kiosk run` or `kiosk replay` on this data directory"
    )


def __getattr__(name: str) -> Any:
    """``SyncClient`` and ``Outbox``, imported when first asked for."""
    if name == "SyncClient":
        from kiosk.sync.client import SyncClient

        return SyncClient
    if name == "Outbox":
        from kiosk.sync.outbox import Outbox

        return Outbox
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
