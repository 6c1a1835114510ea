"""Login throttling: who is asking (the peer, or a trusted proxy's ``X-Forwarded-For``), how long
a (name, address) must wait after its failures, and the security log of every failure.

A pause grows with the failures of one name from one address (none for the first
:data:`FREE_FAILURES`, then :data:`FIRST_PAUSE_S` doubling up to :data:`MAX_PAUSE_S`), and with
the distinct names failing from one address (guessing across names). Failures from elsewhere
never pause anyone, so an attacker hammering a doctor's name from one place cannot keep the
doctor, logging in with the right password from their own place, out. ``X-Forwarded-For`` counts
only when the peer is a proxy the operator named (``--trusted-proxy``); otherwise anyone could
claim a fresh address with each try. Failures are kept in the database, so every station process
behind one PostgreSQL shares them.
"""

from __future__ import annotations

import ipaddress
import logging
from collections.abc import Iterable, Sequence

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from station import db
from station.db import login_failures

Network = ipaddress.IPv4Network | ipaddress.IPv6Network

#: failures of one name from one address before the first pause
FREE_FAILURES = 3
#: distinct names failing from one address before that address pauses
FREE_NAMES = 20
FIRST_PAUSE_S = 2.0
MAX_PAUSE_S = 15 * 60.0
#: failures older than this are forgotten
WINDOW_S = 3600.0

log = logging.getLogger("station.security")


def parse_proxies(values: Iterable[str]) -> tuple[Network, ...]:
    """``--trusted-proxy`` values (an address or a network such as 10.0.0.0/24); ValueError names
    the one that is neither."""
    networks = []
    for value in values:
        try:
            networks.append(ipaddress.ip_network(value.strip(), strict=False))
        except ValueError:
            raise ValueError(f"--trusted-proxy {value!r}: not an IP address or network") from None
    return tuple(networks)


def _ip(text: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address | None:
    try:
        return ipaddress.ip_address(text.strip().strip("[]"))
    except ValueError:
        return None


def client_address(peer: str | None, forwarded_for: Sequence[str], trusted: Sequence[Network]) -> str:
    """The address a request came from: the peer itself, unless the peer is a trusted proxy;
    then the right-most ``X-Forwarded-For`` hop that is not a trusted proxy (hops left of it were
    written by the client and prove nothing)."""
    address = _ip(peer or "")
    if address is None:
        return (peer or "?")[:64]
    hops = [hop for header in forwarded_for for hop in header.split(",")]
    while any(address in network for network in trusted) and hops:
        before = _ip(hops.pop())
        if before is None:  # a proxy wrote something that is not an address: stop at the proxy
            break
        address = before
    return str(address)


def pause_after(failures: int, free: int = FREE_FAILURES) -> float:
    """Seconds to wait after the last of ``failures`` failures before the next try."""
    if failures < free:
        return 0.0
    return min(FIRST_PAUSE_S * 2 ** min(failures - free, 32), MAX_PAUSE_S)


def _lock(connection: Connection, address: str) -> None:
    """Serialise admissions from one address, so parallel tries cannot all pass the count before
    any is recorded: PostgreSQL takes an advisory lock for the transaction; on SQLite the first
    write (the clean-up that follows) takes the database's write lock until commit."""
    if connection.dialect.name == "postgresql":
        connection.execute(sa.text("SELECT pg_advisory_xact_lock(727275, hashtext(:a))"), {"a": address})


def admit(engine: Engine, name: str, address: str) -> tuple[float, int]:
    """May a password be checked now for this name from this address? ``(0, n)`` when it may: the
    try is then already counted as the pair's n-th failure, until :func:`record_success` forgives
    it; ``(seconds left, n)`` when the pair or the address is paused (nothing is counted)."""
    name, address = name[:64], address[:64]
    with engine.begin() as connection:
        _lock(connection, address)
        now = db.now()  # after the lock: a colleague's try admitted meanwhile is not in our future
        connection.execute(login_failures.delete().where(login_failures.c.at < now - WINDOW_S))
        pair_count, pair_last = connection.execute(
            sa.select(sa.func.count(), sa.func.max(login_failures.c.at)).where(
                login_failures.c.name == name, login_failures.c.address == address
            )
        ).one()
        names, address_last = connection.execute(
            sa.select(sa.func.count(sa.distinct(login_failures.c.name)), sa.func.max(login_failures.c.at)).where(
                login_failures.c.address == address
            )
        ).one()
        # a count that earns no pause makes no one wait (tries in flight are counted too: two
        # colleagues logging in together from one address were refused for each other's)
        pair_pause, address_pause = pause_after(pair_count), pause_after(names, FREE_NAMES)
        wait = max(
            0.0,
            pair_last + pair_pause - now if pair_pause else 0.0,
            address_last + address_pause - now if address_pause else 0.0,
        )
        if wait > 0:
            return wait, pair_count
        connection.execute(login_failures.insert().values(name=name, address=address, at=now))
    return 0.0, pair_count + 1


def log_failure(name: str, address: str, count: int) -> None:
    """Note a wrong name or password (``count``: the pair's failures in the window)."""
    log.warning(
        "login failed: name %r from %s (wrong name or password; %d failure(s) in the last hour)",
        name[:64],
        address[:64],
        count,
    )


def record_success(connection: Connection, name: str, address: str) -> None:
    """The right password from this address: its failures for this name (this try's included)
    are forgiven."""
    connection.execute(
        login_failures.delete().where(login_failures.c.name == name[:64], login_failures.c.address == address[:64])
    )


def log_refused(name: str, address: str, wait: float) -> None:
    """Note a try refused unchecked because its pair (or its address) is paused."""
    log.warning("login refused: name %r from %s (paused after failures, %.0f s left)", name[:64], address[:64], wait)
