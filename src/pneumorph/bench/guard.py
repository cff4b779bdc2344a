"""The bench's guard: every request checked before a route sees it (hosts, signed sessions,
same-origin JSON, counted bodies) and one error format (:func:`error_body`); the application:
:mod:`pneumorph.bench.app`.
"""

from __future__ import annotations

import hashlib
import logging
import os
import secrets
from pathlib import Path
from typing import Any

from fastapi.responses import JSONResponse
from starlette.requests import ClientDisconnect, cookie_parser

from pneumorph.errors import BodyTooLargeError

COOKIE = "pneumorph_session"
MAX_UNIT_FILE = 64 * 1024  # bytes of an uploaded unit TOML
MAX_BODY = 1 << 20  # bytes of a JSON request
MAX_UPLOAD = MAX_UNIT_FILE + 16 * 1024  # bytes of a unit upload: the file and the form around it

log = logging.getLogger("pneumorph.bench")

SAFE_METHODS = ("GET", "HEAD", "OPTIONS")
UPLOAD_ROUTES = ("/api/jobs/table",)  # multipart; every other route that takes a body takes JSON
LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")


def error_body(field: str, message: str) -> dict[str, Any]:
    """The bench's one error format, ``{"error": {"field", "message"}}`` (the message bounded to one short line).

    Examples
    --------
    >>> error_body("top", "top must be a whole number")
    {'error': {'field': 'top', 'message': 'top must be a whole number'}}
    >>> len(error_body("unit", "x" * 10_000)["error"]["message"])
    500
    """
    text = " ".join(str(message).split())
    return {"error": {"field": str(field)[:64], "message": text if len(text) <= 500 else text[:497] + "..."}}


def error(status: int, field: str, message: str, headers: dict[str, str] | None = None) -> JSONResponse:
    """An error response in the bench's one format."""
    return JSONResponse(error_body(field, message), status_code=status, headers=headers)


def host_name(value: str) -> str:
    """The host of a ``Host`` header or a URL's netloc, lower case, without port, brackets or final dot.

    Examples
    --------
    >>> host_name("LocalHost:8000"), host_name("[::1]:8000"), host_name("127.0.0.1")
    ('localhost', '::1', '127.0.0.1')
    """
    value = value.strip().lower()
    if value.startswith("["):
        return value[1:value.find("]")] if "]" in value else value
    return value.rsplit(":", 1)[0].rstrip(".") if value.count(":") == 1 else value.rstrip(".")


class Signing:
    """The server's session cookies: random ids signed with a secret of this server (itsdangerous).

    The secret is kept in the state folder (``session.key``, readable by its owner only), so
    a restarted server knows its sessions; a cookie the server did not sign is no session.

    Examples
    --------
    >>> import tempfile
    >>> sign = Signing(Path(tempfile.mkdtemp()))
    >>> value = sign.issue()
    >>> sign.check(value) == value.split(".")[0], sign.check("0" * 32), sign.check("")
    (True, None, None)
    """

    def __init__(self, state: Path) -> None:
        from itsdangerous import Signer

        key = state / "session.key"
        try:
            secret = key.read_bytes()
        except FileNotFoundError:
            secret = b""
        if len(secret) < 32:
            secret = secrets.token_bytes(32)
            fd = os.open(key, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
            with os.fdopen(fd, "wb") as out:
                out.write(secret)
        self._signer = Signer(secret, salt="pneumorph-bench-session", digest_method=hashlib.sha256)

    def issue(self) -> str:
        """A new signed session cookie value (the session id and its signature)."""
        return self._signer.sign(secrets.token_hex(16)).decode("ascii")

    def check(self, value: str) -> str | None:
        """The session id of a cookie value this server signed, else None."""
        from itsdangerous import BadSignature

        if not value or len(value) > 200:
            return None
        try:
            return self._signer.unsign(value.encode("latin-1")).decode("ascii")
        except (BadSignature, UnicodeError):
            return None


class Guard:
    """ASGI middleware in front of every route: hosts, sessions, cross-site refusals, body limits, 500s.

    In order, for each HTTP request:

    1. the ``Host`` header must name a host the server was started for (``allowed_hosts``):
       a page on another name whose DNS points here (DNS rebinding) gets a 400;
    2. the session is the signed cookie's (:class:`Signing`), else a new one sent back with
       the response (HttpOnly, SameSite=Strict); other cookies, even malformed, are ignored;
    3. a request that may change something (any method but GET, HEAD, OPTIONS) is refused
       (403) when it comes from another site (an ``Origin`` other than this server's, or a
       ``Sec-Fetch-Site`` other than same-origin), and (415) unless its body is JSON
       (``application/json``; multipart for the unit upload): a cross-site form or a
       ``text/plain`` POST cannot start work;
    4. the body is counted as it arrives, whatever ``Content-Length`` says (chunked bodies
       have none): past ``max_body`` bytes (``max_upload`` for the upload) the request ends
       with a 413 and the rest is never read;
    5. an unexpected error is a 500 in the one error format, logged in a few bounded lines
       (no body; a client that went away is logged in one line, without a traceback).
    """

    def __init__(self, app: Any, signing: Signing, allowed_hosts: tuple[str, ...], max_body: int = MAX_BODY,
                 max_upload: int = MAX_UPLOAD) -> None:
        self.app = app
        self.signing = signing
        self.allowed = tuple(host_name(h) for h in allowed_hosts)
        self.max_body, self.max_upload = int(max_body), int(max_upload)

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope["headers"]}
        host = headers.get("host", "")
        if host_name(host) not in self.allowed:
            return await error(400, "host", f"this bench serves {', '.join(self.allowed)} only, not "
                                            f"{host[:60]!r}")(scope, receive, send)
        jar = cookie_parser(headers.get("cookie", ""))
        sid = self.signing.check(jar.get(COOKIE, ""))
        cookie = None
        if sid is None:
            value = self.signing.issue()
            sid = value.split(".")[0]
            cookie = f"{COOKIE}={value}; HttpOnly; Max-Age={30 * 86400}; Path=/; SameSite=strict".encode()
        scope.setdefault("state", {})["session"] = sid
        started = False

        async def reply(message: Any) -> None:
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
                if cookie is not None:
                    message["headers"] = [*message.get("headers", []), (b"set-cookie", cookie)]
            await send(message)

        refusal = self.refusal(scope, headers)
        if refusal is not None:
            return await refusal(scope, receive, reply)
        limit = self.max_upload if scope["path"] in UPLOAD_ROUTES else self.max_body
        length = headers.get("content-length")
        if length is not None and (not length.isdigit() or int(length) > limit):
            return await error(413, "body", str(BodyTooLargeError(limit)), {"Connection": "close"})(
                scope, receive, reply)
        seen = 0

        async def counted() -> Any:
            nonlocal seen
            message = await receive()
            if message["type"] == "http.request":
                seen += len(message.get("body", b""))
                if seen > limit:
                    raise BodyTooLargeError(limit)
            return message

        try:
            await self.app(scope, counted, reply)
        except BodyTooLargeError as exc:
            if not started:
                await error(413, "body", str(exc), {"Connection": "close"})(scope, receive, reply)
        except ClientDisconnect:
            log.info("%s %s: the client went away", scope["method"], scope["path"][:100])
        except Exception as exc:
            log.error("%s %s failed: %s", scope["method"], scope["path"][:100], brief(exc))
            if not started:
                await error(500, "server", "an internal error of the bench; the server's log says where")(
                    scope, receive, reply)

    def refusal(self, scope: Any, headers: dict[str, str]) -> JSONResponse | None:
        """The response refusing a request that may change something, from another site or not JSON; else None."""
        if scope["method"] in SAFE_METHODS:
            return None
        origin = headers.get("origin")
        host = headers.get("host", "")
        if origin is not None and origin.lower() not in (f"http://{host}".lower(), f"https://{host}".lower()):
            return error(403, "origin", f"requests from another site ({origin[:80]}) may not change anything here")
        site = headers.get("sec-fetch-site")
        if site is not None and site not in ("same-origin", "none"):
            return error(403, "origin", f"requests from another site (Sec-Fetch-Site: {site[:40]}) may not change "
                                        "anything here")
        if scope["method"] == "DELETE":
            return None
        kind = headers.get("content-type", "").split(";")[0].strip().lower()
        wanted = "multipart/form-data" if scope["path"] in UPLOAD_ROUTES else "application/json"
        if kind != wanted:
            return error(415, "content-type", f"this route takes {wanted}, not {kind[:60] or 'an unnamed type'}")
        return None


def brief(exc: BaseException, frames: int = 8) -> str:
    """An exception in a few bounded lines: its type and message (at most 300 characters) and its last frames.

    Examples
    --------
    >>> brief(ValueError("x" * 1000)).count("x") <= 300
    True
    """
    import traceback

    text = " ".join(str(exc).split())
    where = [f"{Path(f.filename).name}:{f.lineno} {f.name}" for f in traceback.extract_tb(exc.__traceback__)[-frames:]]
    return f"{type(exc).__name__}: {text[:300]} (at {' <- '.join(reversed(where))})"
