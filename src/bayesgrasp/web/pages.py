"""The pages: the planning page at ``/``, Swagger UI at ``/docs``, ReDoc at ``/redoc``.

Swagger UI's and ReDoc's scripts are served from the package's own files
(``/static/vendor``), so the documentation pages work offline.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from fastapi import APIRouter, FastAPI
from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html
from fastapi.responses import FileResponse, HTMLResponse, RedirectResponse
from fastapi.staticfiles import StaticFiles

__all__ = ["VENDOR", "mount_static", "router", "static_dir"]

VENDOR = "/static/vendor"

router = APIRouter(include_in_schema=False)


def static_dir() -> Path:
    """The folder of the page's files."""
    return Path(str(resources.files("bayesgrasp.web") / "static"))


@router.get("/")
async def page() -> FileResponse:
    """The planning page."""
    return FileResponse(static_dir() / "index.html", media_type="text/html")


@router.get("/index.html")
async def page_alias() -> RedirectResponse:
    """The planning page's other address."""
    return RedirectResponse("/")


@router.get("/docs")
async def swagger() -> HTMLResponse:
    """Swagger UI of the OpenAPI schema, from local assets."""
    return get_swagger_ui_html(
        openapi_url="/openapi.json",
        title="bayesgrasp API",
        swagger_js_url=f"{VENDOR}/swagger-ui-bundle.js",
        swagger_css_url=f"{VENDOR}/swagger-ui.css",
        swagger_favicon_url=f"{VENDOR}/favicon-32x32.png",
    )


@router.get("/redoc")
async def redoc() -> HTMLResponse:
    """ReDoc of the OpenAPI schema, from local assets."""
    return get_redoc_html(
        openapi_url="/openapi.json",
        title="bayesgrasp API",
        redoc_js_url=f"{VENDOR}/redoc.standalone.js",
        redoc_favicon_url=f"{VENDOR}/favicon-32x32.png",
        with_google_fonts=False,
    )


def mount_static(app: FastAPI) -> None:
    """Serve the page's files under ``/static``."""
    app.mount("/static", StaticFiles(directory=str(static_dir())), name="static")
