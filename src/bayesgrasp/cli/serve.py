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
    timeout: Annotated[
        float,
        typer.Option(
            "--timeout",
            "--time-limit",
            min=0.01,
            metavar="S",
            help="Seconds a request's work may take, waiting included; then its worker is "
            "killed and the answer is 503. A request may ask for less (?timeout=S).",
        ),
    ] = 10.0,
    workers: Annotated[
        int,
        typer.Option(
            min=1,
            metavar="N",
            help="Worker processes for heavy work: policies, noise-aware plans, simulations, "
            "simulation jobs.",
        ),
    ] = 2,
    quick_workers: Annotated[
        int,
        typer.Option(min=1, metavar="N", help="Worker processes for squeeze, push and plans."),
    ] = 2,
    figure_workers: Annotated[
        int, typer.Option(min=1, metavar="N", help="Worker processes drawing figures.")
    ] = 1,
    worker_memory: Annotated[
        int,
        typer.Option(
            min=0,
            metavar="MB",
            help="Memory a worker may take beyond its libraries (then 503 and the worker is "
            "replaced); 0: no cap.",
        ),
    ] = 2048,
    queue: Annotated[
        int,
        typer.Option(
            min=0, metavar="N", help="Requests that may wait for a worker in each lane (then 503)."
        ),
    ] = 16,
    job_timeout: Annotated[
        float,
        typer.Option(min=1, metavar="S", help="Seconds a simulation job may take."),
    ] = 600.0,
) -> None:
    """Serve the page (draw or upload a part, see its plans) and the JSON API at /api/v1.

    Planning runs in worker processes: a quick lane (squeeze, push, plans), a lane drawing
    figures and a heavy lane (policies, noise-aware plans, simulations), each with a bounded
    queue, so a slow request never delays a light one. Work past its time limit is stopped and its
    worker replaced. The API's reference is at /docs and /redoc.
    """
    try:
        import uvicorn

        from ..web.app import Limits, create_app
        from ..web.gallery import default_data_dir
    except ImportError as exc:
        from ..errors import MissingExtraError

        raise MissingExtraError(exc.name or "fastapi", "web") from None
    folder = data if data is not None else default_data_dir()
    limits = Limits(
        time_limit=timeout,
        gallery_rows=gallery_rows,
        workers=workers,
        quick_workers=quick_workers,
        figure_workers=figure_workers,
        worker_memory=worker_memory or None,
        queue=queue,
        job_time_limit=job_timeout,
    )
    web = create_app(folder, limits)
    typer.echo(
        f"bayesgrasp: serving http://{host}:{port}/ (API /api/v1, reference /docs; gallery in "
        f"{folder}); {quick_workers} quick, {figure_workers} figure and {workers} heavy workers, "
        f"time limit {timeout:g} s, queue {queue}; Ctrl-C stops",
        err=True,
    )
    uvicorn.run(web, host=host, port=port, log_level="warning")
