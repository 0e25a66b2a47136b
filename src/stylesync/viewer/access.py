"""Who may open the web viewer: the person given its address, from the viewer's own page.

The viewer's address carries a random token (``/?token=...``, as Jupyter's does). A page request with the token
gets the page and a cookie holding it (``HttpOnly``, ``SameSite=Strict``), so that the page's own files and its
websocket, requested by the browser without the query, carry it. Every other request needs the cookie (or the
token in its query). A websocket handshake must also come from the viewer's own origin: a browser sends the
``Origin`` of the page that opens the socket, so a page of another site the user visits cannot connect to
``127.0.0.1:PORT`` and pause or reset the session, even if the cookie were sent. Refusals are 403 responses.

viser serves its page and its websocket from one ``websockets`` server; :func:`install` wraps the
``process_request`` hook of that server (in the viewer's own process, viewer/process.py), before viser starts it.
"""

from __future__ import annotations

import hmac
import http
import http.cookies
import secrets
from collections.abc import Callable
from typing import Any
from urllib.parse import parse_qs, urlsplit

COOKIE = "stylesync_viewer_token"


def new_token() -> str:
    """A random token for one viewer (128 bits, URL-safe)."""
    return secrets.token_urlsafe(16)


def _same(a: str | None, b: str) -> bool:
    return a is not None and hmac.compare_digest(a.encode(), b.encode())


def _tokens(request: Any) -> tuple[str | None, str | None]:
    """The token of the request's query and of its cookie (None where absent)."""
    query = parse_qs(urlsplit(request.path).query).get("token", [None])[0]
    jar = http.cookies.SimpleCookie()
    try:
        jar.load(request.headers.get("Cookie", ""))
    except http.cookies.CookieError:
        pass
    cookie = jar[COOKIE].value if COOKIE in jar else None
    return query, cookie


def origin_allowed(origin: str | None, host: str | None) -> bool:
    """A handshake's ``Origin`` is the viewer's own (``http(s)://HOST:PORT`` as the request's ``Host``), or absent
    (a client that is not a browser, e.g. a script with the token)."""
    if origin is None:
        return True
    return host is not None and origin in (f"http://{host}", f"https://{host}")


def gate(token: str, inner: Callable[[Any, Any], Any] | None) -> Callable[[Any, Any], Any]:
    """A ``process_request`` hook that refuses what :mod:`this module <stylesync.viewer.access>` describes and hands
    the rest to ``inner`` (viser's own page server, or None)."""

    def process_request(connection: Any, request: Any) -> Any:
        query, cookie = _tokens(request)
        authorised = _same(query, token) or _same(cookie, token)
        if request.headers.get("Upgrade", "").lower() == "websocket":
            if not origin_allowed(request.headers.get("Origin"), request.headers.get("Host")):
                return connection.respond(http.HTTPStatus.FORBIDDEN, "stylesync viewer: another origin\n")
            if not authorised:
                return connection.respond(http.HTTPStatus.FORBIDDEN, "stylesync viewer: token required\n")
            return inner(connection, request) if inner is not None else None
        if not authorised:
            return connection.respond(http.HTTPStatus.FORBIDDEN,
                                      "stylesync viewer: open the address the run printed (it holds a token)\n")
        response = inner(connection, request) if inner is not None else None
        if response is not None and _same(query, token) and not _same(cookie, token):
            response.headers["Set-Cookie"] = f"{COOKIE}={token}; Path=/; HttpOnly; SameSite=Strict"
        return response

    return process_request


def install(token: str) -> None:
    """Make every ``websockets`` server started from now on in this process use :func:`gate` (the viewer's process
    runs only viser's)."""
    import websockets.asyncio.server as ws_server

    global _token
    _token = token
    serve = ws_server.serve
    if getattr(serve, "_stylesync_gated", False):
        return

    class GatedServe(serve):  # type: ignore[misc, valid-type]
        _stylesync_gated = True

        def __init__(self, *args: Any, **kwargs: Any) -> None:
            assert _token is not None
            kwargs["process_request"] = gate(_token, kwargs.get("process_request"))
            super().__init__(*args, **kwargs)

    ws_server.serve = GatedServe  # type: ignore[misc]


_token: str | None = None  # the token of the viewer this process serves (install)
