"""``squeeze`` and ``push``: a part's transfer functions and their stable orientations."""

from __future__ import annotations

import typer

from .common import emit_json
from .options import JsonOpt, PriorOpt, command_app, part_options
from .specs import PartSpec

app = command_app()


@app.command()
@part_options
def squeeze(part: PartSpec, prior: PriorOpt = "uniform", as_json: JsonOpt = False) -> None:
    """Stable orientations of a squeeze, their basins and probabilities after one squeeze."""
    from .. import report
    from ..geometry.curved import squeeze_model
    from ..model.prior import parse_prior

    p = part.load()
    pr = parse_prior(prior)
    f = squeeze_model(p)[1]
    if as_json:
        emit_json(report.squeeze_json(p, f, pr))
    else:
        typer.echo(report.squeeze_table(p, f, pr))


@app.command()
@part_options
def push(part: PartSpec, prior: PriorOpt = "uniform", as_json: JsonOpt = False) -> None:
    """Stable orientations of a push and a push-grasp, their basins and probabilities.

    The push turns the part down its radius function about the centre of mass until an edge
    lies flat against the pushing jaw (on the gripper's -x side); the table names that edge.
    """
    from .. import report
    from ..geometry.curved import push_model
    from ..model.prior import parse_prior

    p = part.load()
    pr = parse_prior(prior)
    r, f, g = push_model(p)  # a curved part's exact pushes
    if as_json:
        emit_json(report.push_json(p, r, f, g, pr))
    else:
        typer.echo(report.push_table(p, r, f, g, pr))
