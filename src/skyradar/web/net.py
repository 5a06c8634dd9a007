"""Network safety of the live display: loopback hosts, same-origin WebSockets, binding the port.

The display has no login: anyone who can open its port can watch the run. It therefore binds to
127.0.0.1 by default, warns when told to bind elsewhere, and accepts WebSocket connections only
from pages it served itself (a page on another site must not drive or read the replay). Bound to
loopback, it also answers only requests addressed to a loopback name (:class:`LoopbackHostOnly`).
"""

from __future__ import annotations

import errno
import ipaddress
import socket
from typing import Any
from urllib.parse import urlsplit

from skyradar.errors import InputError

__all__ = [
    "LoopbackHostOnly",
    "bind_socket",
    "host_is_loopback",
    "is_loopback",
    "origin_allowed",
]

_DEFAULT_PORTS = {"http": 80, "https": 443, "ws": 80, "wss": 443}


def is_loopback(host: str) -> bool:
    """True if ``host`` (an address or ``localhost``) is reachable only from this machine.

    A host name other than ``localhost`` counts as not loopback: it may resolve anywhere.

    Examples
    --------
    >>> is_loopback("127.0.0.1"), is_loopback("::1"), is_loopback("localhost")
    (True, True, True)
    >>> is_loopback("0.0.0.0"), is_loopback("192.168.1.20"), is_loopback("example.org")
    (False, False, False)
    """
    name = host.strip().strip("[]").lower()
    if name == "localhost":
        return True
    try:
        return ipaddress.ip_address(name).is_loopback
    except ValueError:
        return False


def _host_port(netloc: str, scheme: str) -> tuple[str, int] | None:
    try:
        parts = urlsplit(f"{scheme}://{netloc}")
        port = parts.port or _DEFAULT_PORTS.get(scheme)
    except ValueError:  # a malformed port
        return None
    if not parts.hostname or port is None:
        return None
    return parts.hostname.lower(), port


def origin_allowed(origin: str | None, host_header: str | None, scheme: str = "http") -> bool:
    """May a WebSocket whose handshake carries ``Origin: origin`` talk to a server reached as ``host_header``?

    Allowed: no ``Origin`` (not a browser: browsers always send one, so a missing header cannot be
    a page on another site), the same host and port as the ``Host`` header, or a loopback name
    (``localhost``, ``127.0.0.1``, ``[::1]``) on that port when the server is reached on a loopback
    name. Everything else (another site, another port, ``null``) is refused.

    Examples
    --------
    >>> origin_allowed("http://127.0.0.1:8765", "127.0.0.1:8765")
    True
    >>> origin_allowed("http://localhost:8765", "127.0.0.1:8765")
    True
    >>> origin_allowed("http://evil.example", "127.0.0.1:8765")
    False
    >>> origin_allowed("http://localhost:9999", "127.0.0.1:8765")
    False
    >>> origin_allowed("null", "127.0.0.1:8765")
    False
    """
    if origin is None:
        return True
    if not host_header:
        return False
    served = _host_port(host_header, scheme)
    parts = urlsplit(origin.strip())
    came = _host_port(parts.netloc, parts.scheme.lower()) if parts.scheme.lower() in _DEFAULT_PORTS else None
    if served is None or came is None:
        return False
    if came == served:
        return True
    both_local = is_loopback(came[0]) and is_loopback(served[0])
    return both_local and came[1] == served[1]


def bind_socket(host: str, port: int) -> socket.socket:
    """A TCP socket bound to ``host:port`` (not yet listening), or :class:`InputError` naming them.

    Binding here, before the server starts, turns "port already taken" and "no such address" into
    one clear line instead of a server log and a wrong exit code; the server then uses this socket,
    so nothing can take the port in between.

    Examples
    --------
    >>> sock = bind_socket("127.0.0.1", 0)
    >>> sock.getsockname()[0]
    '127.0.0.1'
    >>> sock.close()
    """
    if not 0 <= port <= 65535:
        raise InputError(f"serve: option '--port' must be 0..65535, got {port}")
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as exc:
        raise InputError(
            f"serve: option '--host' {host!r} is not an address of this machine ({exc})"
        ) from exc
    family, kind, proto, _, address = infos[0]
    sock = socket.socket(family, kind, proto)
    try:
        # Same as uvicorn: a restart may reuse a port whose old connections are in TIME_WAIT.
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind(address)
    except OSError as exc:
        sock.close()
        reason = "address already in use" if exc.errno == errno.EADDRINUSE else (exc.strerror or str(exc))
        where = f"[{host}]:{port}" if ":" in host else f"{host}:{port}"
        raise InputError(f"serve: cannot listen on {where}: {reason}") from exc
    return sock


def host_is_loopback(host_header: str | None) -> bool:
    """True if a request's ``Host`` header names this machine by a loopback name or address.

    Examples
    --------
    >>> host_is_loopback("127.0.0.1:8765"), host_is_loopback("[::1]:8765"), host_is_loopback("localhost")
    (True, True, True)
    >>> host_is_loopback("attacker.example:8765"), host_is_loopback(None)
    (False, False)
    """
    hp = _host_port(host_header, "http") if host_header else None
    return hp is not None and is_loopback(hp[0])


class LoopbackHostOnly:
    """ASGI wrapper refusing requests whose ``Host`` is not a loopback name (HTTP 403, WebSocket 1008).

    A server bound to 127.0.0.1 is still reachable from a web page through DNS rebinding (a name
    that first resolves to the attacker, then to 127.0.0.1); such requests carry the attacker's
    name in ``Host``, so refusing other names closes that door.

    Parameters
    ----------
    app : ASGI application
        The application requests with a loopback ``Host`` pass on to.

    Examples
    --------
    Driven directly with ASGI messages (no server): a loopback ``Host`` reaches the app, another name
    gets 403 over HTTP and close code 1008 over a WebSocket.

    >>> import asyncio
    >>> async def app(scope, receive, send):
    ...     await send({"type": "http.response.start", "status": 200, "headers": []})
    >>> sent = []
    >>> async def send(message):
    ...     sent.append(message)
    >>> async def receive():
    ...     return {}
    >>> guard = LoopbackHostOnly(app)
    >>> requests = [("http", b"127.0.0.1:8765"), ("http", b"evil.example"), ("websocket", b"evil.example")]
    >>> for kind, host in requests:
    ...     asyncio.run(guard({"type": kind, "headers": [(b"host", host)]}, receive, send))
    >>> [m.get("status", m.get("code")) for m in sent if m["type"] != "http.response.body"]
    [200, 403, 1008]
    """

    def __init__(self, app: Any):
        self.app = app

    async def __call__(self, scope: dict, receive: Any, send: Any) -> None:
        if scope["type"] in ("http", "websocket"):
            headers = dict(scope.get("headers") or [])
            host = headers.get(b"host", b"").decode("latin-1")
            if not host_is_loopback(host):
                if scope["type"] == "websocket":
                    await send({"type": "websocket.close", "code": 1008})
                    return
                body = b"forbidden: this display answers only to localhost / 127.0.0.1 / [::1]\n"
                await send(
                    {
                        "type": "http.response.start",
                        "status": 403,
                        "headers": [
                            (b"content-type", b"text/plain"),
                            (b"content-length", str(len(body)).encode()),
                        ],
                    }
                )
                await send({"type": "http.response.body", "body": body})
                return
        await self.app(scope, receive, send)
