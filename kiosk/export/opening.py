"""Session records shared by the command-line tools: opening the store, a stored session's trace.

``kiosk qos trace SESSION`` (dispatched here by ``kiosk.commands.qos``) prints a stored session's QoS
context trace in the trace format of ``python -m qos replay``, which then reproduces the metrics
the session recorded.
"""

from __future__ import annotations

import argparse
import sys
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from kiosk.config import Config, ConfigError, configured_questionnaire, load_config
from kiosk.core.adaptation import MODEL
from kiosk.core.questionnaire.definition import canonical
from kiosk.store.database import StorageError, Store, StoredSession
from kiosk.store.migrations import InForce

__all__ = ["MODEL", "in_force_of", "open_store", "session_trace", "trace_main"]


def in_force_of(config: Config) -> InForce:
    """What an upgrade of the kiosk database attaches to the sessions stored before definitions
    and identities were captured: the configuration's questionnaire (with its band set) and its
    site, kiosk and FHIR systems, dated now."""
    from kiosk.export import export_identity, site_from_config

    return InForce(
        canonical(configured_questionnaire(config)),
        export_identity(site_from_config(config)),
        datetime.now(UTC).isoformat().replace("+00:00", "Z"),
    )


def open_store(data_dir: str | None, **options: Any) -> Store:
    """The existing store in ``data_dir``, or in the configured data directory; never creates one
    (ConfigError/StorageError). ``options`` are :class:`Store`'s (``in_force``: what an upgrade
    attaches to sessions stored before definitions were captured; default: the configuration's,
    :func:`in_force_of`)."""
    options.setdefault("in_force", lambda: in_force_of(load_config()))
    return Store.open(Path(data_dir) if data_dir else load_config().data_dir, create=False, **options)


def session_trace(stored: StoredSession, model: str = MODEL):  # -> qos.Trace
    """A stored session's context trace as a ``qos.Trace`` of ``model`` (the kiosk's ``qos_model``)."""
    from qos import Trace

    return Trace.from_events(
        model,
        stored.trace,
        description=f"session {stored.id} (patient {stored.patient_id}, started {stored.started_at})",
    )


def trace_main(argv: list[str]) -> int:
    """`kiosk qos trace SESSION [--json] [-o FILE] [--data-dir DIR]`; exit 2 on an unknown session."""
    parser = argparse.ArgumentParser(prog="kiosk qos trace", description="print a stored session's QoS context trace")
    parser.add_argument("session", help="session id (or a unique prefix of it)")
    parser.add_argument("--json", action="store_true", help="JSON instead of YAML")
    parser.add_argument("-o", "--output", metavar="FILE", help="write to FILE (owner-only) instead of stdout")
    parser.add_argument("--data-dir", help="data directory (default: from the kiosk configuration)")
    parser.add_argument("--model", help="the QoS model the session ran (default: the configuration's qos_model)")
    args = parser.parse_args(argv)
    try:
        model = args.model or load_config().qos_model
        with open_store(args.data_dir) as store:
            stored = store.session(args.session)
    except (ConfigError, StorageError) as exc:
        print(f"kiosk qos trace: {exc}", file=sys.stderr)
        return 2
    except KeyError as exc:
        print(f"kiosk qos trace: {exc.args[0]}", file=sys.stderr)
        return 2
    trace = session_trace(stored, model)
    text = trace.to_json() + "\n" if args.json else trace.to_yaml()
    if args.output:
        from kiosk.export import ExportError, write_export

        try:
            write_export(args.output, text)
        except ExportError as exc:
            print(f"kiosk qos trace: {exc}", file=sys.stderr)
            return 2
    else:
        sys.stdout.write(text)
    return 0
