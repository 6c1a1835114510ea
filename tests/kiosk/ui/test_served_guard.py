"""The served kiosk's gate, in Debian's Chromium against a real `kiosk serve`: no device key, no
kiosk (page and websocket); the key once, then a cookie that outlives the browser; a websocket
from another origin refused although the browser holds the cookie; the busy page at the cap."""

from __future__ import annotations

import http.server
import socketserver
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from kiosk.config import load_config
from kiosk.ui.serve.guard import COOKIE, token_digest
from kiosk.ui.widgets.text import ui_text

from .serving import CHROMIUM, CHROMIUM_ARGS, PATIENCE_S, TOKEN, Painted, free_port, serve, wait_until

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="Debian's chromium is not installed (.ci/run installs it)"),
]

WELCOME = ui_text("en", "choose_language")

#: opens the kiosk's websocket from whatever page runs it: "open" or "refused"
OPEN_SOCKET = """url => new Promise(done => {
    const ws = new WebSocket(url);
    ws.onopen = () => { ws.close(); done("open"); };
    ws.onerror = () => done("refused");
    ws.onclose = () => done("refused");
})"""


async def _browser(pw, profile: Path | None = None):
    if profile is None:
        browser = await pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        return browser, await browser.new_context(viewport={"width": 1200, "height": 780})
    context = await pw.chromium.launch_persistent_context(
        str(profile), executable_path=CHROMIUM, args=CHROMIUM_ARGS, viewport={"width": 1200, "height": 780}
    )
    return None, context


async def test_without_the_key_the_page_and_its_websocket_are_refused(tmp_path):
    from playwright.async_api import async_playwright

    with serve(tmp_path) as served:
        async with async_playwright() as pw:
            browser, context = await _browser(pw)
            page = await context.new_page()
            painted = Painted(page)
            response = await page.goto(served.url("/?fontsize=20"))
            assert response.status == 403
            assert "not set up as a kiosk" in await page.inner_text("body")
            assert painted.sockets == [], "the refusal page opens no websocket"
            # a page of the kiosk's own origin that has no key cannot open the websocket either
            assert (
                await page.evaluate(OPEN_SOCKET, served.url("/ws?width=80&height=24").replace("http", "ws"))
                == "refused"
            )
            wrong = await page.goto(served.url("/?token=not-the-key"))
            assert wrong.status == 403 and await context.cookies() == []
            await browser.close()
        assert not served.database.exists(), "no kiosk process ran, so no session was stored"


async def test_the_key_once_then_a_cookie_that_outlives_the_browser(tmp_path):
    from playwright.async_api import async_playwright

    with serve(tmp_path) as served:
        async with async_playwright() as pw:
            _, context = await _browser(pw, tmp_path / "profile")
            page = await context.new_page()
            painted = Painted(page)
            await page.goto(served.url(f"/?token={TOKEN}&fontsize=20"))
            assert page.url == served.url("/?fontsize=20"), "the key leaves the address bar at once"
            (cookie,) = await context.cookies()
            assert (cookie["name"], cookie["value"], cookie["httpOnly"], cookie["sameSite"]) == (
                COOKIE,
                TOKEN,
                True,
                "Strict",
            )
            assert cookie["expires"] > 0, "kept beyond this browser session"
            await wait_until(page, painted.shows(WELCOME), "the welcome screen")
            await context.close()  # the kiosk's browser restarts (same profile)

            _, context = await _browser(pw, tmp_path / "profile")
            page = await context.new_page()
            painted = Painted(page)
            response = await page.goto(served.url("/?fontsize=20"))
            assert response.status == 200
            await wait_until(page, painted.shows(WELCOME), "the welcome screen after a restart")
            await context.close()


class _ForeignSite(socketserver.ThreadingMixIn, http.server.HTTPServer):
    daemon_threads = True


async def test_a_websocket_from_another_origin_is_refused_though_the_browser_has_the_cookie(tmp_path):
    from playwright.async_api import async_playwright

    # another web page on this machine (another port: the same site, so SameSite sends the cookie)
    (tmp_path / "site").mkdir()
    (tmp_path / "site" / "index.html").write_text("<!doctype html><title>another page</title>")
    handler = lambda *args: http.server.SimpleHTTPRequestHandler(*args, directory=str(tmp_path / "site"))  # noqa: E731
    foreign = _ForeignSite(("127.0.0.1", free_port()), handler)
    threading.Thread(target=foreign.serve_forever, daemon=True).start()
    try:
        with serve(tmp_path) as served:
            async with async_playwright() as pw:
                browser, context = await _browser(pw)
                page = await context.new_page()
                await page.goto(served.url(f"/?token={TOKEN}&fontsize=20"))
                socket_url = served.url("/ws?width=80&height=24").replace("http", "ws")
                other = await context.new_page()
                await other.goto(f"http://127.0.0.1:{foreign.server_address[1]}/index.html")
                assert [c["name"] for c in await context.cookies(socket_url.replace("ws", "http"))] == [COOKIE]
                assert await other.evaluate(OPEN_SOCKET, socket_url) == "refused"
                # the same socket from the kiosk's own page opens: the Origin made the difference
                assert await page.evaluate(OPEN_SOCKET, socket_url) == "open"
                await browser.close()
            assert "Origin 'http://127.0.0.1:" in served.log.read_text()
    finally:
        foreign.shutdown()


async def test_at_the_cap_a_clear_busy_page_and_a_closed_tab_frees_its_place(tmp_path):
    from playwright.async_api import async_playwright

    with serve(tmp_path, "serve_max_sessions: 1\n") as served:
        async with async_playwright() as pw:
            browser, context = await _browser(pw)
            first = await context.new_page()
            painted = Painted(first)
            await first.goto(served.url(f"/?token={TOKEN}&fontsize=20"))
            await wait_until(first, painted.shows(WELCOME), "the first screen's kiosk")

            second = await context.new_page()
            response = await second.goto(served.url("/?fontsize=20"))
            assert response.status == 503
            assert "The kiosk is in use" in await second.inner_text("body")

            await first.close()  # its kiosk process is reaped, and the place is free again
            painted = Painted(second)
            response = await second.goto(served.url("/?fontsize=20"), timeout=PATIENCE_S * 1000)
            assert response.status == 200
            await wait_until(second, painted.shows(WELCOME), "the second screen's kiosk")
            await browser.close()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--host", "0.0.0.0"], "refusing to serve on 0.0.0.0 without TLS"),
        (["--host", "192.168.1.20", "--tls-cert", "cert.pem"], "--tls-cert and --tls-key go together"),
        (["--host", "0.0.0.0", "--insecure-network"], "needs --public-url"),
    ],
)
def test_a_network_address_needs_tls_or_an_explicit_flag(tmp_path, args, message):
    config = tmp_path / "config.yaml"
    config.write_text('serve_token_sha256: "' + "0" * 64 + '"\n')
    done = subprocess.run(
        [sys.executable, "-m", "kiosk", "serve", *args, "--config", str(config)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=PATIENCE_S,
    )
    assert done.returncode == 2 and done.stderr.count("\n") == 1 and message in done.stderr, done.stderr


def test_serving_without_a_device_key_is_refused_with_the_way_to_set_one_up(tmp_path):
    config = tmp_path / "config.yaml"
    config.write_text("language: en\n")
    done = subprocess.run(
        [sys.executable, "-m", "kiosk", "serve", "--config", str(config)],
        capture_output=True,
        text=True,
        timeout=PATIENCE_S,
    )
    assert done.returncode == 2 and "kiosk serve --new-token" in done.stderr and done.stderr.count("\n") == 1
    made = subprocess.run(
        [sys.executable, "-m", "kiosk", "serve", "--new-token", "--config", str(config)],
        capture_output=True,
        text=True,
        timeout=PATIENCE_S,
    )
    assert made.returncode == 0 and "?token=" in made.stdout
    token = made.stdout.split("?token=")[1].split("&")[0]
    assert token not in config.read_text() and "language: en" in config.read_text()
    assert oct(config.stat().st_mode & 0o777) == "0o600"


@pytest.mark.parametrize(
    ("text", "show_score"), [("{}\n", False), ("# bed 2\n{show_score_to_patient: true}\n", True)], ids=["empty", "flow"]
)
def test_a_new_device_key_is_written_into_a_configuration_in_flow_style(tmp_path, text, show_score):
    """Issue 32: after ``{}`` the added key was a YAML error at line 2."""
    config = tmp_path / "config.yaml"
    config.write_text(text)
    made = subprocess.run(
        [sys.executable, "-m", "kiosk", "serve", "--new-token", "--config", str(config)],
        capture_output=True,
        text=True,
        timeout=PATIENCE_S,
    )
    assert made.returncode == 0 and "?token=" in made.stdout and made.stderr == "", made.stderr
    token = made.stdout.split("?token=")[1].split("&")[0]
    loaded = load_config(config, environ={})
    assert loaded.serve_token_sha256 == token_digest(token)
    assert loaded.show_score_to_patient is show_score and text.count("#") == config.read_text().count("#")
