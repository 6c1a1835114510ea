"""``kiosk station``: start the ward station, or administer it.

    kiosk station [--db URL] [--host H] [--port P] [--tls-cert F --tls-key F] [--insecure-lan]
                  [--trusted-proxy ADDRESS]...
    kiosk station add-user NAME --role nurse|doctor [--password-file F] [--db URL]
    kiosk station passwd NAME [--password-file F] [--db URL]    ends every login of NAME
    kiosk station remove-user NAME [--db URL]                   ends every login of NAME
    kiosk station add-kiosk NAME [--db URL]        prints the kiosk's token (shown once)
    kiosk station migrate --db OWNER_URL [--grant APP_ROLE]...   PostgreSQL: the owner migrates
    kiosk station revoke-kiosk NAME [--db URL]

Without ``--db`` the station keeps one SQLite file in its data directory (``$KIOSK_STATION_DIR``
or the user's data directory; directory 0700, file 0600). It listens on 127.0.0.1 unless told
otherwise, and refuses any other address without TLS unless ``--insecure-lan`` says the network
is trusted. On PostgreSQL the schema's owner runs ``migrate --grant APP_ROLE`` and the station
runs as the app role, which cannot switch off the audit trail's guard (:mod:`station.roles`).
"""

from __future__ import annotations

import argparse
import getpass
import ipaddress
import logging
import sys
from pathlib import Path

from fileio.bounded import BadFile, read_text
from kiosk.core.visits import DEFAULT_ID_PATTERN, pattern_problem
from station import auth, batteries, db, known, roles, throttle, times

ADMIN = ("add-user", "passwd", "remove-user", "add-kiosk", "revoke-kiosk", "migrate", "add-definition")


class UsageError(Exception):
    """A mistake on the command line (one sentence, exit 2)."""


def _db_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--db",
        metavar="URL",
        help="database URL: postgresql://user@host/dbname, or sqlite:///path "
        "(default: station.sqlite3 in $KIOSK_STATION_DIR or the user data directory)",
    )


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="kiosk station",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="The ward station: kiosks report to it, staff watch the ward, answer doctor calls and "
        "validate results.",
        epilog="administration (each takes --db too):\n"
        "  kiosk station add-user NAME --role nurse|doctor [--password-file F]\n"
        "  kiosk station passwd NAME [--password-file F]   a new password; ends NAME's logins\n"
        "  kiosk station remove-user NAME                  ends NAME's logins too\n"
        "  kiosk station add-kiosk NAME      prints the kiosk's token (shown once)\n"
        "  kiosk station revoke-kiosk NAME\n"
        "  kiosk station add-definition FILE.yaml   an instrument this site uses: its total formula may run\n"
        "  kiosk station migrate --db OWNER_URL --grant APP_ROLE   (PostgreSQL) migrate as the owner; the\n"
        "      station then runs as APP_ROLE, which cannot change or switch off the audit trail",
    )
    _db_option(parser)
    parser.add_argument(
        "--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1: this machine only)"
    )
    parser.add_argument("--port", type=int, default=8443, help="port (default 8443)")
    parser.add_argument("--tls-cert", type=Path, metavar="PEM", help="TLS certificate chain (PEM)")
    parser.add_argument("--tls-key", type=Path, metavar="PEM", help="TLS private key (PEM)")
    parser.add_argument(
        "--trusted-proxy",
        action="append",
        default=[],
        metavar="ADDRESS",
        help="a reverse proxy (address or network) whose X-Forwarded-For names the client; "
        "repeat for each (default: none, the peer's own address counts)",
    )
    parser.add_argument(
        "--patient-id-pattern",
        metavar="REGEX",
        default=DEFAULT_ID_PATTERN,
        help="the site's patient identifiers, matched whole (default: digits with at most four letters "
        "in front, such as NHC-0012345); the kiosks' patient_id_pattern should say the same",
    )
    parser.add_argument(
        "--time-zone",
        metavar="ZONE",
        default="",
        help="the site's time zone, in which staff read every time (an IANA name such as Europe/Madrid; "
        "default: the machine's own)",
    )
    parser.add_argument(
        "--battery",
        action="append",
        default=[],
        metavar="NAME=ID,ID,...",
        help="a battery the site runs, its instruments in the order patients do them (as the kiosks' "
        "instruments:); the order form offers it by name and keeps that order; repeat for each",
    )
    parser.add_argument(
        "--formula-timeout",
        type=float,
        default=2.0,
        metavar="SECONDS",
        help="the longest a known definition's total formula may run on one result (default 2)",
    )
    parser.add_argument(
        "--insecure-lan",
        action="store_true",
        help="allow a non-loopback --host without TLS (only on a network you trust)",
    )
    return parser


def _admin_parser(command: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=f"kiosk station {command}")
    _db_option(parser)
    if command == "migrate":
        parser.add_argument(
            "--grant",
            action="append",
            default=[],
            metavar="APP_ROLE",
            help="PostgreSQL: let this role run the station (tables read and written, the audit "
            "trail only read and added to); repeat for several",
        )
        return parser
    if command == "add-definition":
        parser.add_argument("file", type=Path, help="the instrument file (YAML), as the kiosks run it")
        return parser
    parser.add_argument("name", help="the user's or kiosk's name")
    if command == "add-user":
        parser.add_argument("--role", required=True, choices=auth.ROLES)
    if command in ("add-user", "passwd"):
        parser.add_argument(
            "--password-file", type=Path, help="read the password from this file's first line (default: ask)"
        )
    return parser


def _url(option: str | None) -> str:
    """The database URL; a SQLite file, default or given, is created owner-only."""
    try:
        if option is None:
            return db.sqlite_url(db.default_data_dir())
        if option.startswith("sqlite:///") and option != "sqlite:///:memory:":
            return db.private_sqlite(Path(option.removeprefix("sqlite:///")))
    except OSError as exc:
        raise UsageError(f"cannot create the station database {exc.filename}: {exc.strerror}") from None
    return option


def _password(path: Path | None) -> str:
    if path is not None:
        try:  # the project's bounded reader: a device or a huge file named by mistake is one line
            text = read_text(path, 4096)
        except BadFile as exc:
            raise UsageError(f"the password file: {exc}") from None
        return text.splitlines()[0] if text else ""
    if not sys.stdin.isatty():
        raise UsageError("no terminal to ask for the password: give --password-file FILE")
    first = getpass.getpass("Password: ")
    if first != getpass.getpass("Again: "):
        raise UsageError("the two passwords differ")
    return first


def _admin(command: str, argv: list[str]) -> int:
    args = _admin_parser(command).parse_args(argv)
    if command in ("add-user", "passwd"):
        password = _password(args.password_file)  # ask before touching the database
    if command == "migrate":
        return _migrate(args)
    engine = db.open_database(_url(args.db))
    roles.check_privileges(engine)
    if command == "add-user":
        auth.add_user(engine, args.name, args.role, password)
        print(f"user {args.name} ({args.role}) saved")
    elif command == "passwd":
        ended = auth.set_password(engine, args.name, password)
        print(f"user {args.name}: password changed; {ended} login(s) ended")
    elif command == "remove-user":
        ended = auth.remove_user(engine, args.name)
        print(f"user {args.name} removed; {ended} login(s) ended")
    elif command == "add-definition":
        from kiosk.core.questionnaire import QuestionnaireError

        try:
            found, sha = known.register_file(engine, args.file, getpass.getuser())
        except QuestionnaireError as exc:
            raise UsageError(f"{args.file}: {exc}") from None
        print(f"definition {found} {sha} registered: the station runs its total formula")
    elif command == "add-kiosk":
        token = auth.add_kiosk(engine, args.name)
        print(f"kiosk {args.name} added; its token (shown only now; put it in the kiosk's config as station.token):")
        print(token)
    else:
        auth.revoke_kiosk(engine, args.name)
        print(f"kiosk {args.name}: token revoked")
    return 0


def _migrate(args: argparse.Namespace) -> int:
    if args.grant and not (args.db or "").startswith(("postgresql:", "postgresql+", "postgres:")):
        raise UsageError("--grant is for PostgreSQL: a SQLite station is one owner-only file, with no roles")
    engine = db.make_engine(_url(args.db))
    db.migrate(engine)
    print(f"database {engine.url.render_as_string()} migrated to the newest schema")
    for role in args.grant:
        roles.grant_app_role(engine, role)
        print(f"role {role}: may read and write the station's tables; the audit trail only read and added to")
    return 0


def _check_listen(args: argparse.Namespace) -> None:
    if bool(args.tls_cert) != bool(args.tls_key):
        raise UsageError("give both --tls-cert and --tls-key, or neither")
    for path in (args.tls_cert, args.tls_key):
        if path is not None and not path.is_file():
            raise UsageError(f"no such file {path}")
    if not 0 < args.port < 65536:
        raise UsageError(f"--port {args.port}: choose 1-65535")
    try:
        loopback = ipaddress.ip_address(args.host).is_loopback
    except ValueError:
        loopback = args.host == "localhost"
    if not loopback and not args.tls_cert and not args.insecure_lan:
        raise UsageError(
            f"--host {args.host} would let other machines in without encryption: give --tls-cert "
            "and --tls-key, or --insecure-lan on a network you trust"
        )


def _serve(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    _check_listen(args)
    try:
        proxies = throttle.parse_proxies(args.trusted_proxy)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    if (problem := pattern_problem(args.patient_id_pattern)) is not None:
        raise UsageError(problem.replace("patient_id_pattern", "--patient-id-pattern", 1))
    try:
        zone = times.zone_named(args.time_zone)
    except times.ZoneError as exc:
        raise UsageError(str(exc)) from None
    try:
        site_batteries = batteries.parse_all(args.battery)
    except ValueError as exc:
        raise UsageError(f"--battery {exc}") from None
    import sqlalchemy as sa
    import uvicorn

    from station import errors
    from station.web import create_app

    engine = db.open_database(_url(args.db))
    roles.check_privileges(engine)
    warning = roles.guard_warning(engine)
    if warning:
        print(warning, file=sys.stderr, flush=True)
    from station import formulas

    formulas.TIMEOUT_S = max(0.1, args.formula_timeout)
    try:
        known.register_shipped(engine)
    except sa.exc.SQLAlchemyError as exc:  # a database that takes no write: /healthz says so too
        print(f"kiosk station: cannot register the shipped instruments: {errors.reason(exc)}", file=sys.stderr)
    app = create_app(
        engine,
        https=bool(args.tls_cert),
        trusted_proxies=proxies,
        id_pattern=args.patient_id_pattern,
        batteries=site_batteries,
        zone=zone,
    )
    scheme = "https" if args.tls_cert else "http"
    print(f"ward station on {scheme}://{args.host}:{args.port}/ (database {engine.url.render_as_string()})", flush=True)
    # failed and refused logins are logged here (station.security), one line each
    logging.basicConfig(level=logging.WARNING, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    uvicorn.run(
        app,
        host=args.host,
        port=args.port,
        log_level="warning",
        access_log=False,
        # uvicorn would trust X-Forwarded-For from 127.0.0.1 by default: the station
        # reads it itself, from --trusted-proxy only (station.throttle)
        proxy_headers=False,
        ssl_certfile=str(args.tls_cert) if args.tls_cert else None,
        ssl_keyfile=str(args.tls_key) if args.tls_key else None,
        timeout_graceful_shutdown=2,
        # kiosks keep their connection between batches; closing it after 5 s idle made
        # them retry on a half-closed socket
        timeout_keep_alive=75,
    )
    return 0


def main(argv: list[str]) -> int:
    """Entry point of ``kiosk station``; returns the exit status."""
    try:
        if argv and argv[0] in ADMIN:
            return _admin(argv[0], argv[1:])
        return _serve(argv)
    except (UsageError, auth.AuthError, roles.RoleError, db.DatabaseError) as exc:
        print(f"kiosk station: {exc}", file=sys.stderr)
        return 2
