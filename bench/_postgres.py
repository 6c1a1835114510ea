"""A throwaway PostgreSQL server from Debian's binaries, in a temporary directory: for the station
tests (one per test session) and ``bench/station.py``.

initdb refuses to run as root, so as root the server runs as the Debian ``postgres`` user (its
directory lives outside pytest's root-only temp tree for that reason)."""

from __future__ import annotations

import glob
import os
import shutil
import socket
import subprocess
import tempfile
from collections.abc import Callable
from pathlib import Path


def pg_bin() -> Path | None:
    """Debian's newest PostgreSQL binaries, if installed."""
    found = sorted(glob.glob("/usr/lib/postgresql/*/bin/initdb"))
    return Path(found[-1]).parent if found else None


def _as_postgres(argv: list[str]) -> list[str]:
    return ["runuser", "-u", "postgres", "--", *argv] if os.geteuid() == 0 else argv


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_postgres(bin_dir: Path) -> tuple[str, Callable[[], None]]:
    """Start a server on a free 127.0.0.1 port; returns its superuser URL and a stop function."""
    base = Path(tempfile.mkdtemp(prefix="station-pg-"))
    data, sockets = base / "data", base / "sock"
    data.mkdir(mode=0o700)
    sockets.mkdir()
    if os.geteuid() == 0:
        for path in (base, data, sockets):
            shutil.chown(path, "postgres")
        base.chmod(0o755)
    port = free_port()
    subprocess.run(
        _as_postgres(
            [str(bin_dir / "initdb"), "-D", str(data), "-U", "postgres", "--auth=trust", "--no-sync", "-E", "UTF8"]
        ),
        check=True,
        capture_output=True,
        cwd=base,
    )
    subprocess.run(
        _as_postgres(
            [
                str(bin_dir / "pg_ctl"),
                "-D",
                str(data),
                "-l",
                str(base / "log"),
                "-w",
                "-t",
                "60",
                "-o",
                f"-p {port} -k {sockets} -c listen_addresses=127.0.0.1 -c fsync=off -c max_connections=300",
                "start",
            ]
        ),
        check=True,
        capture_output=True,
        cwd=base,
    )

    def stop() -> None:
        subprocess.run(
            _as_postgres([str(bin_dir / "pg_ctl"), "-D", str(data), "-m", "immediate", "stop"]),
            capture_output=True,
            cwd=base,
        )
        shutil.rmtree(base, ignore_errors=True)

    return f"postgresql://postgres@127.0.0.1:{port}/postgres", stop


def create_database(server_url: str, name: str) -> str:
    """A new empty database on the server; returns its URL."""
    import psycopg

    with psycopg.connect(server_url, autocommit=True) as connection:
        connection.execute(f"CREATE DATABASE {name}")
    return server_url.rsplit("/", 1)[0] + "/" + name
