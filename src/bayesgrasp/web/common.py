"""What the API's routes share: the prefix, the ``timeout`` parameter, error answers.

Every error is a JSON body ``{detail, error, status}``
(:class:`~bayesgrasp.web.models.ErrorBody`); :class:`BodyLimit` answers a body over the
server's limit with a 413 before it is read.
"""

from __future__ import annotations

from typing import Any

from fastapi import Query
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from pydantic import ValidationError

__all__ = ["API", "TIMEOUT", "BodyLimit", "error_response", "one_line"]

API = "/api/v1"

TIMEOUT = Query(
    None,
    ge=0.01,
    le=86_400,
    description="Seconds this request's work may take (at most the server's time limit, "
    "the default).",
)


def error_response(
    status: int, detail: str, kind: str, retry_after: int | None = None
) -> JSONResponse:
    """The error answer ``{detail, error, status}``, with ``Retry-After`` when given."""
    headers = {"Retry-After": str(retry_after)} if retry_after is not None else None
    return JSONResponse(
        {"detail": detail, "error": kind, "status": status}, status_code=status, headers=headers
    )


class BodyLimit:
    """ASGI middleware: a request body over ``max_bytes`` is answered 413, unread past the limit."""

    def __init__(self, app: Any, max_bytes: int) -> None:
        self.app = app
        self.max_bytes = max_bytes

    def _too_large(self) -> JSONResponse:
        return error_response(
            413,
            f"the request body is larger than the limit of {self.max_bytes} bytes",
            "body-too-large",
        )

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        """Pass the request on, or answer 413 when its body is over the limit."""
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = dict(scope.get("headers") or [])
        length = headers.get(b"content-length")
        if length is not None:
            try:
                declared = int(length)
            except ValueError:
                declared = self.max_bytes + 1
            if declared > self.max_bytes:
                await self._too_large()(scope, receive, send)
                return
            await self.app(scope, receive, send)
            return
        # no length declared (chunked): read the body here, counting, then hand it on
        chunks: list[bytes] = []
        seen = 0
        while True:
            message = await receive()
            if message["type"] != "http.request":
                await self.app(scope, receive, send)  # the client went away
                return
            chunk = message.get("body", b"")
            seen += len(chunk)
            if seen > self.max_bytes:
                await self._too_large()(scope, receive, send)
                return
            chunks.append(chunk)
            if not message.get("more_body", False):
                break
        body = b"".join(chunks)
        replayed = False

        async def replay() -> Any:
            nonlocal replayed
            if replayed:
                return await receive()
            replayed = True
            return {"type": "http.request", "body": body, "more_body": False}

        await self.app(scope, replay, send)


def one_line(exc: RequestValidationError | ValidationError) -> str:
    """The validation errors as one line: ``part.vertices.0: message; ...``."""
    parts = []
    for err in exc.errors():
        loc = ".".join(str(x) for x in err.get("loc", ()) if x != "body")
        parts.append(f"{loc or 'body'}: {err.get('msg', 'invalid')}")
    return "; ".join(parts) or "invalid request"
