"""`kiosk serve`: serve the kiosk to a browser on a touch display with textual-serve.

A touchscreen kiosk runs Chromium in kiosk mode on the same machine. Staff set the screen up once:

    kiosk serve --new-token          # prints http://127.0.0.1:8000/?token=…; open it once in Chromium
    kiosk serve                      # then the kiosk's browser opens http://127.0.0.1:8000/?fontsize=28

Every browser connection starts its own ``kiosk run`` process, so a closed tab never leaves a
half-run session behind (the session core resumes it). What guards it (the device key, the
Origin/Host check, the cap on processes) is in :mod:`kiosk.ui.serve.guard`.

The server binds to localhost unless asked otherwise: patient data must not be reachable from the
network by default, and another address is refused unless the page is served over TLS
(``--tls-cert``/``--tls-key``) or ``--insecure-network`` says plain HTTP on the network is meant.
"""

from __future__ import annotations

import argparse
import ipaddress
import os
import secrets
import shlex
import ssl
import sys
from pathlib import Path
from urllib.parse import urlsplit

#: the address a kiosk's own browser uses; anything else exposes the kiosk to the network
LOCALHOST = "127.0.0.1"
_LOOPBACK_NAMES = ("127.0.0.1", "localhost", "[::1]")


def build_command(run_args: list[str]) -> str:
    """The shell command textual-serve starts for each browser connection: ``kiosk run ARGS``
    (``exec``: the shell becomes the kiosk, so stopping the connection's process stops the kiosk)."""
    return "exec " + shlex.join([sys.executable, "-m", "kiosk", "run", *run_args])


def run_args_problem(run_args: list[str]) -> str | None:
    """What is wrong with the options passed on to `kiosk run`, or None: checked before serving,
    because every browser connection would otherwise only show `kiosk run`'s usage error."""
    from kiosk.ui.options import run_parser

    parser = run_parser()
    parser.exit_on_error = False  # report the problem as one line here, not argparse's usage text
    try:
        _, unknown = parser.parse_known_args(run_args)
    except argparse.ArgumentError as error:
        return str(error)
    if unknown:
        return f"unrecognised arguments: {' '.join(unknown)} (neither `kiosk serve` nor `kiosk run` takes them)"
    return None


def is_loopback(host: str) -> bool:
    """``host`` is reachable from this machine only."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def served_hosts(host: str, port: int, public_url: str | None, tls: bool) -> set[str]:
    """The ``Host`` values browsers reach the kiosk by. Raises ValueError for a listening address
    that names no host (0.0.0.0) without ``--public-url``."""
    default_port = 443 if tls else 80
    if public_url is not None:
        parts = urlsplit(public_url)
        if parts.scheme != ("https" if tls else "http") or not parts.hostname:
            raise ValueError(f"--public-url {public_url!r} must be an {'https' if tls else 'http'}:// address")
        names = [parts.hostname if ":" not in parts.hostname else f"[{parts.hostname}]"]
        port = parts.port or default_port
    elif is_loopback(host):
        names = list(_LOOPBACK_NAMES)
    elif host in ("0.0.0.0", "::", ""):
        raise ValueError(
            f"listening on every address ({host or 'all'}) needs --public-url, the address the "
            "kiosk's browser opens (Host and Origin are checked against it)"
        )
    else:
        names = [host if ":" not in host else f"[{host}]"]
    hosts = {f"{name}:{port}" for name in names}
    if port == default_port:
        hosts |= set(names)  # browsers leave the default port out of Host
    return hosts


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="kiosk serve",
        description="Serve the kiosk to a browser (a touch display running Chromium), to browsers that hold the "
        "device key set up by --new-token. Options not listed here are passed to `kiosk run` (for example "
        "--data-dir, --config).",
    )
    parser.add_argument(
        "--host", default=LOCALHOST, help="address to listen on (default %(default)s: this machine only)"
    )
    parser.add_argument("--port", type=int, default=8000, help="TCP port (default %(default)s)")
    parser.add_argument(
        "--new-token",
        action="store_true",
        help="make a new device key, keep its digest in the configuration, print the address "
        "to open once in the kiosk's browser, and exit (the old key stops working)",
    )
    parser.add_argument("--tls-cert", type=Path, metavar="PEM", help="serve over HTTPS with this certificate")
    parser.add_argument("--tls-key", type=Path, metavar="PEM", help="the certificate's private key")
    parser.add_argument(
        "--public-url",
        metavar="URL",
        help="the address browsers open when it is not --host:--port (e.g. behind a name)",
    )
    parser.add_argument(
        "--insecure-network",
        action="store_true",
        help="allow a network address without TLS (patient data in clear on the network)",
    )
    return parser


def _config_path(run_args: list[str]) -> Path | None:
    from kiosk.ui.options import run_parser

    return run_parser().parse_known_args(run_args)[0].config


def _new_token(run_args: list[str], host: str, port: int, tls: bool) -> int:
    from kiosk.config import ConfigError, default_config_path, write_settings
    from kiosk.ui.serve.guard import token_digest

    path = _config_path(run_args) or (
        Path(os.environ["KIOSK_CONFIG"]) if os.environ.get("KIOSK_CONFIG") else default_config_path()
    )
    token = secrets.token_urlsafe(32)
    try:
        write_settings(path, {"serve_token_sha256": token_digest(token)})
    except ConfigError as error:
        print(f"kiosk serve: {error}", file=sys.stderr)
        return 2
    name = "127.0.0.1" if is_loopback(host) else host
    print(
        f"A new device key is set (its digest is in {path}). Open this address once in the kiosk's browser;\n"
        f"it keeps the key in a cookie and drops it from the address:\n\n"
        f"  {'https' if tls else 'http'}://{name}:{port}/?token={token}&fontsize=28\n\n"
        "Anyone with this address can use the kiosk: do not write it down."
    )
    return 0


def _tls(cert: Path | None, key: Path | None) -> ssl.SSLContext | None:
    if cert is None and key is None:
        return None
    if cert is None or key is None:
        raise ValueError("--tls-cert and --tls-key go together")
    context = ssl.create_default_context(ssl.Purpose.CLIENT_AUTH)
    try:
        context.load_cert_chain(cert, key)
    except (OSError, ssl.SSLError) as error:
        raise ValueError(f"cannot use {cert} and {key} for TLS: {getattr(error, 'strerror', None) or error}") from None
    return context


def main(argv: list[str]) -> int:
    """Run the web server until interrupted; returns the process exit status."""
    args, run_args = _parser().parse_known_args(argv)
    if not 0 < args.port < 65536:
        print(f"kiosk serve: --port must be between 1 and 65535, got {args.port}", file=sys.stderr)
        return 2
    if (problem := run_args_problem(run_args)) is not None:
        print(f"kiosk serve: {problem}", file=sys.stderr)
        return 2
    tls = args.tls_cert is not None or args.tls_key is not None
    if not is_loopback(args.host) and not tls and not args.insecure_network:
        print(
            f"kiosk serve: refusing to serve on {args.host} without TLS: patient data would cross the network "
            "in clear. Give --tls-cert and --tls-key, or --insecure-network if that is really meant.",
            file=sys.stderr,
        )
        return 2
    if args.new_token:
        return _new_token(run_args, args.host, args.port, tls)

    from kiosk.config import ConfigError, load_config
    from kiosk.core.pin import PinGuard
    from kiosk.ui.serve.guard import KioskServer

    try:
        config = load_config(_config_path(run_args))
        hosts = served_hosts(args.host, args.port, args.public_url, tls)
        context = _tls(args.tls_cert, args.tls_key)
    except (ConfigError, ValueError) as error:
        print(f"kiosk serve: {error}", file=sys.stderr)
        return 2
    if config.serve_token_sha256 is None:
        print(
            "kiosk serve: no device key is set up, so no browser could open the kiosk: run "
            "`kiosk serve --new-token` (with the same --config) and open the address it prints once "
            "in the kiosk's browser",
            file=sys.stderr,
        )
        return 2
    if not is_loopback(args.host):
        print(
            f"kiosk serve: warning: listening on {args.host}, so other machines can reach the "
            "kiosk (they still need its device key)",
            file=sys.stderr,
        )
    if (warning := PinGuard(config.pin_secret).warning) is not None:
        print(f"kiosk serve: warning: {warning}", file=sys.stderr)

    server = KioskServer(
        build_command(run_args),
        host=args.host,
        port=args.port,
        hosts=hosts,
        token_sha256=config.serve_token_sha256,
        max_sessions=config.serve_max_sessions,
        ssl_context=context,
    )
    try:
        server.serve()
    except OSError as error:  # port in use, address not on this machine
        print(f"kiosk serve: cannot listen on {args.host}:{args.port}: {error.strerror or error}", file=sys.stderr)
        return 1
    return 0
