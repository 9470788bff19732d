"""The run specs below the surfaces (``bayesgrasp.runs``): what the CLI re-exports, what they do.

The command line, the web service and sweeps share one definition of a run; the CLI only
adds its parsing (typer) and printing. Checked here: the CLI's names are the runs' objects,
the runs package loads no command-line code, a mesh PART reads as the part readers read it,
and the point-cloud note goes to the caller's ``note`` only.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from numpy.testing import assert_allclose

from bayesgrasp.cli import common as cli_common
from bayesgrasp.cli import noisy as cli_noisy
from bayesgrasp.cli import specs as cli_specs
from bayesgrasp.errors import PartError
from bayesgrasp.io import resolve_part
from bayesgrasp.model.noise import NoiseModel
from bayesgrasp.model.problem import Problem
from bayesgrasp.runs import noisy, specs
from bayesgrasp.shapes import load

ROOT = Path(__file__).resolve().parents[2]
MESH = ROOT / "examples" / "bracket.obj"


def test_the_cli_names_are_the_runs_objects() -> None:
    for name in cli_specs.__all__:
        assert getattr(cli_specs, name) is getattr(specs, name), name
    assert cli_common.PLAN_NAMES is specs.PLAN_NAMES
    assert cli_common.simulate_inputs is specs.simulate_inputs
    assert cli_common.guaranteed_plan is specs.guaranteed_plan
    assert issubclass(cli_noisy.NoisyRun, noisy.NoisyRun)
    assert cli_noisy.Planned is noisy.Planned


def test_runs_load_no_command_line_code() -> None:
    probe = (
        "import sys, json\n"
        "import bayesgrasp.runs.specs, bayesgrasp.runs.noisy\n"
        "print(json.dumps(sorted(m for m in sys.modules "
        "if m.startswith(('typer', 'click', 'bayesgrasp.cli', 'bayesgrasp.web')))))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True
    ).stdout
    assert json.loads(out) == []


def test_the_noisy_run_is_the_cli_run() -> None:
    """The base run and the CLI's subclass plan and write the same document."""
    pb = Problem.build(load("key"))
    noise = NoiseModel.of("uniform:2", None)
    base = noisy.NoisyRun(noise, None, None, False, True)
    cli = cli_noisy.NoisyRun(noise, None, None, False, True)
    a, b = base.document(base.plan(pb)), cli.document(cli.plan(pb))
    assert a.pop("provenance")["version"] == b.pop("provenance")["version"]
    assert a == b
    assert a["schema"] == "bayesgrasp.plan/2" and "noisy_options" in a


def test_a_mesh_part_reads_as_the_part_readers_read_it() -> None:
    """PartSpec's own mesh path against io.resolve_part's (solid.parts.mesh_part)."""
    for pose in (None, "1"):
        mine = specs.PartSpec(str(MESH), element=pose).load()
        theirs = resolve_part(str(MESH), element=pose)
        assert mine.name == theirs.name
        assert_allclose(mine.hull.vertices, theirs.hull.vertices, atol=1e-12)
        assert_allclose(mine.center_of_mass, theirs.center_of_mass, atol=1e-12)


def test_a_mesh_part_refuses_layers_and_curves() -> None:
    with pytest.raises(PartError, match="a mesh has no layers or curves"):
        specs.PartSpec(str(MESH), layer="0").load()
    with pytest.raises(PartError, match="drop --layer, --flatten-tol"):
        specs.PartSpec(str(MESH), flatten_tol=0.1).load_solid()


def test_the_point_cloud_note_goes_to_the_caller(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "cloud.csv"  # the points cross themselves in file order
    path.write_text("".join(f"{x},{y}\n" for x, y in [(0, 0), (2, 2), (2, 0), (0, 2)]))
    notes: list[str] = []
    part = specs.PartSpec(str(path), note=notes.append).load()
    assert part.hull.n_sides == 4 and len(notes) == 1
    assert "point cloud: the part is their convex hull" in notes[0]
    assert "--com X,Y" in notes[0]
    specs.PartSpec(str(path)).load()  # no note: nothing printed
    assert capsys.readouterr() == ("", "")
    # The note is no part of the spec's value.
    assert specs.PartSpec("key", note=notes.append) == specs.PartSpec("key")


def test_run_inputs_leave_out_options_not_given() -> None:
    spec = specs.ProblemSpec(max_actions=2)
    assert specs.run_inputs(None, spec) == {"max_actions": 2}
    part = specs.PartSpec("key", fmt=specs.PartFormat.json, layer="L")
    got = specs.run_inputs(part, spec)
    assert got["format"] == "json" and got["layer"] == "L" and got["element"] is None
