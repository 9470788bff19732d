"""``serve``: the web page and the HTTP API (the ``web`` extra)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .options import command_app

app = command_app()


@app.command()
def serve(
    host: Annotated[
        str, typer.Option(help="Address to bind (default: this machine only).")
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option(min=0, max=65535, help="Port to listen on.")] = 8000,
    data: Annotated[
        Path | None,
        typer.Option(
            "--data",
            metavar="DIR",
            help="Folder of the gallery database (default: the user data folder).",
        ),
    ] = None,
    gallery_rows: Annotated[
        int, typer.Option(min=1, help="Most parts the gallery keeps (the oldest go).")
    ] = 500,
    time_limit: Annotated[
        float, typer.Option(min=0.01, help="Seconds of work a request may take (then 503).")
    ] = 10.0,
) -> None:
    """Serve the page (draw or upload a part, see its plans) and the JSON API at /api/v1."""
    try:
        import uvicorn

        from ..web.app import Limits, create_app
        from ..web.gallery import default_data_dir
    except ImportError as exc:
        from ..errors import MissingExtraError

        raise MissingExtraError(exc.name or "fastapi", "web") from None
    folder = data if data is not None else default_data_dir()
    limits = Limits(time_limit=time_limit, gallery_rows=gallery_rows)
    web = create_app(folder, limits)
    typer.echo(
        f"bayesgrasp: serving http://{host}:{port}/ (API /api/v1, schema /openapi.json; "
        f"gallery in {folder}); Ctrl-C stops",
        err=True,
    )
    uvicorn.run(web, host=host, port=port, log_level="warning")
