"""`kiosk station` on the command line: it stays on this machine unless told, refuses to open to
the network without TLS, serves over TLS with the documented options, keeps its default database
private, and administrators' mistakes are one line and exit 2."""

from __future__ import annotations

import os
import shutil
import ssl
import stat
import subprocess
import sys
import time

import httpx
import pytest

from station import auth, db
from tests.station.conftest import PATIENCE_S, ROOT, free_port

pytestmark = pytest.mark.slow


def kiosk_station(*args: str, env: dict | None = None, stdin: str | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiosk", "station", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=os.environ | (env or {}),
        input=stdin,
        timeout=PATIENCE_S * 2,
    )


@pytest.mark.parametrize(
    "argv, words",
    [
        (["--host", "0.0.0.0"], "without encryption"),
        (["--host", "192.168.1.20", "--tls-cert", "cert.pem"], "both --tls-cert and --tls-key"),
        (["--port", "70000"], "--port 70000"),
        (["--db", "postgresql://nobody@127.0.0.1:1/none"], "cannot open the station database"),
    ],
)
def test_mistakes_are_one_line_and_exit_2(argv, words, tmp_path):
    done = kiosk_station(*argv, env={"KIOSK_STATION_DIR": str(tmp_path / "data")})
    assert done.returncode == 2
    assert words in done.stderr and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_admin_commands_keep_the_default_database_private(tmp_path):
    home = tmp_path / "station-data"
    password = tmp_path / "pw"
    password.write_text("a-doctor-password\n")
    env = {"KIOSK_STATION_DIR": str(home)}
    assert (
        kiosk_station("add-user", "dr.lopez", "--role", "doctor", "--password-file", str(password), env=env).returncode
        == 0
    )
    added = kiosk_station("add-kiosk", "ward3-bed2", env=env)
    assert added.returncode == 0
    token = added.stdout.strip().splitlines()[-1]
    assert stat.S_IMODE(home.stat().st_mode) == 0o700
    for path in home.iterdir():
        assert stat.S_IMODE(path.stat().st_mode) == 0o600, path
    engine = db.open_database(db.sqlite_url(home))
    assert auth.kiosk_for(engine, token) == "ward3-bed2"
    assert auth.login(engine, "dr.lopez", "a-doctor-password", "test").role == "doctor"
    engine.dispose()
    again = kiosk_station("add-kiosk", "ward3-bed2", env=env)
    assert again.returncode == 2 and "revoke it first" in again.stderr
    short = tmp_path / "short"
    short.write_text("abc\n")
    weak = kiosk_station("add-user", "nurse.kim", "--role", "nurse", "--password-file", str(short), env=env)
    assert weak.returncode == 2 and "at least" in weak.stderr
    no_terminal = kiosk_station("add-user", "nurse.kim", "--role", "nurse", env=env, stdin="")
    assert no_terminal.returncode == 2 and "--password-file" in no_terminal.stderr


@pytest.mark.skipif(shutil.which("openssl") is None, reason="openssl makes the test certificate")
def test_tls_options_serve_https_on_a_lan_address(tmp_path):
    cert, key = tmp_path / "cert.pem", tmp_path / "key.pem"
    subprocess.run(
        [
            "openssl",
            "req",
            "-x509",
            "-newkey",
            "rsa:2048",
            "-nodes",
            "-days",
            "1",
            "-subj",
            "/CN=127.0.0.1",
            "-addext",
            "subjectAltName=IP:127.0.0.1",
            "-keyout",
            str(key),
            "-out",
            str(cert),
        ],
        check=True,
        capture_output=True,
    )
    port = free_port()
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "kiosk",
            "station",
            "--db",
            db.sqlite_url(tmp_path / "d"),
            "--host",
            "127.0.0.1",
            "--port",
            str(port),
            "--tls-cert",
            str(cert),
            "--tls-key",
            str(key),
        ],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
    )
    try:
        context = ssl.create_default_context(cafile=str(cert))
        banner = process.stdout.readline().decode()
        assert banner.startswith("ward station on https://")
        response = None
        for _ in range(int(PATIENCE_S * 10)):
            try:
                response = httpx.get(f"https://127.0.0.1:{port}/login", verify=context, timeout=5)
                break
            except httpx.ConnectError:
                if process.poll() is not None:
                    break
                time.sleep(0.1)  # readiness polling, bounded
        assert response is not None and response.status_code == 200
        cookie_flags = httpx.get(f"https://127.0.0.1:{port}/login", verify=context).headers["set-cookie"].lower()
        assert "secure" in cookie_flags and "httponly" in cookie_flags and "samesite=strict" in cookie_flags
        with pytest.raises(httpx.HTTPError):
            httpx.get(f"http://127.0.0.1:{port}/login", timeout=5)
    finally:
        process.terminate()
        process.wait(10)
