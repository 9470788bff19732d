"""write_figures (bayesgrasp.figures.files) and the commands that write figures.

The figures read the problem they are given: no diameter, squeeze or push-grasp function
and no problem is built again while they draw.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

import bayesgrasp.figures
import bayesgrasp.figures.plots
from bayesgrasp.cli import main
from bayesgrasp.figures import diameter_figure, transfer_figure, write_figures
from bayesgrasp.geometry import diameter, push, transfer
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import plan_exact
from bayesgrasp.shapes import load

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
BUILDERS = (
    (diameter, "diameter_function"),
    (transfer, "squeeze_function"),
    (push, "push_grasp_function"),
    (push, "push_function"),
)


class Counter:
    def __init__(self) -> None:
        self.calls: dict[str, int] = {}

    def wrap(self, name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        def counted(*args: Any, **kwargs: Any) -> Any:
            self.calls[name] = self.calls.get(name, 0) + 1
            return fn(*args, **kwargs)

        return counted


@pytest.fixture
def builds(monkeypatch: pytest.MonkeyPatch) -> Iterator[Counter]:
    """Counts every call of the model's builders, wherever a module imported them."""
    counter = Counter()
    for module, name in BUILDERS:
        original = getattr(module, name)
        counted = counter.wrap(name, original)
        for mod in list(sys.modules.values()):
            if mod is not None and getattr(mod, name, None) is original:
                monkeypatch.setattr(mod, name, counted)
    original_build = Problem.build.__func__  # type: ignore[attr-defined]
    counted_build = counter.wrap("Problem.build", original_build)
    monkeypatch.setattr(Problem, "build", classmethod(counted_build))
    yield counter


@pytest.mark.parametrize("actions", ["squeeze", "squeeze,push-grasp"])
def test_write_figures_never_rebuilds_the_model(
    actions: str, tmp_path: Path, builds: Counter
) -> None:
    pb = Problem.build(load("house"), actions=actions)
    option = plan_exact(pb).most_certain_plan
    builds.calls.clear()
    files = write_figures(pb, option, tmp_path, formats=("png",), frames_per_step=4)
    assert builds.calls == {}
    assert [f.name for f in files] == [
        "part.png",
        "diameter.png",
        "transfer.png",
        "plan.png",
        "plan.gif",
    ]


def test_a_part_is_built_into_a_problem_once(builds: Counter) -> None:
    house = load("house")
    builds.calls.clear()
    transfer_figure(house, push_grasp=True)
    assert builds.calls == {
        "Problem.build": 1,
        "diameter_function": 1,
        "squeeze_function": 1,
        "push_grasp_function": 1,
    }
    builds.calls.clear()
    diameter_figure(house)
    assert builds.calls == {"Problem.build": 1, "diameter_function": 1, "squeeze_function": 1}


def test_every_old_name_is_still_importable() -> None:
    old = (
        "PlanAnimation diameter_figure evolution_figure part_figure plan_animation "
        "plan_figure save_animation transfer_figure write_figures"
    ).split()
    for name in old:
        assert getattr(bayesgrasp.figures, name) is getattr(bayesgrasp.figures.plots, name)
    assert {"step_distributions", "nearest_state_mod_pi"} <= set(dir(bayesgrasp.figures.plots))


def is_png(path: Path) -> bool:
    return path.stat().st_size > 1000 and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_plot_writes_png_and_svg(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "figs"
    code = main(["plot", str(EXAMPLES / "peanut.svg"), "--out", str(out), "--no-animation"])
    printed = capsys.readouterr().out.split()
    assert code == 0
    for name in ("part", "diameter", "transfer", "plan"):
        assert is_png(out / f"{name}.png")
        assert (out / f"{name}.svg").read_text().lstrip().startswith("<?xml")
    assert sorted(printed) == sorted(str(p) for p in out.iterdir())


def test_cli_plot_guaranteed_plan_with_animation(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        [
            "plot",
            "rectangle",
            "--plan",
            "guaranteed",
            "--out",
            str(tmp_path),
            "--frames",
            "4",
            "--image-formats",
            "png",
            "--push-grasp",
        ]
    )
    capsys.readouterr()
    assert code == 0
    assert is_png(tmp_path / "plan.png") and is_png(tmp_path / "transfer.png")
    assert (tmp_path / "plan.gif").read_bytes()[:6] == b"GIF89a"
    assert not (tmp_path / "plan.svg").exists()


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["plot", "rectangle", "--image-formats", "jpg"], "--image-formats"),
        (["plan", "rectangle", "--plot", "{tmp}/plan.jpg"], "must end in .png, .svg or .pdf"),
        (["plan", "rectangle", "--plot", "{tmp}/no/such/plan.png"], "no folder"),
        (["plot", "{tmp}/missing.svg", "--out", "{tmp}"], "no such file"),
    ],
)
def test_cli_plot_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], match: str
) -> None:
    code = main([a.format(tmp=tmp_path) for a in argv])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and match in err and "Traceback" not in err


def test_plan_plot_from_a_fresh_process(tmp_path: Path) -> None:
    """The issue's 'done when': `bayesgrasp plan examples/bracket.dxf --plot plan.png`."""
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "bayesgrasp.cli",
            "plan",
            str(EXAMPLES / "bracket.dxf"),
            "--plot",
            "plan.png",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    assert "Bayes plan" in run.stdout
    assert is_png(tmp_path / "plan.png")


def test_write_figures_under_noise(tmp_path: Path) -> None:
    """Under a noise model: the plan figure's stems are the exact distributions under it,
    its title and the animation's caption say the noise, the part's figures are unchanged.

    The exact distributions are checked against 100,000 sampled executions drawing the turn
    error (:func:`~bayesgrasp.sim.kinematic.simulate_kinematic`), within 4 standard errors.
    """
    import math

    import numpy as np

    from bayesgrasp.model.noise import NoiseModel, TurnNoise
    from bayesgrasp.planning.noisy import plan_noisy
    from bayesgrasp.sim.kinematic import simulate_kinematic

    pb = Problem.build(load("key"))
    noise = NoiseModel(TurnNoise("normal", math.radians(3.0)), 0.05)
    res = plan_noisy(pb, noise)
    option = res.bayes_plan.option
    figures: dict[str, Any] = {}
    real = bayesgrasp.figures.files.evolution_figure

    def kept(*args: Any, **kwargs: Any) -> Any:
        fig = real(*args, **kwargs)
        figures.setdefault("plan", fig)  # the first: the noisy run's
        return fig

    anims: list[Any] = []
    real_anim = bayesgrasp.figures.files.plan_animation

    def kept_anim(*args: Any, **kwargs: Any) -> Any:
        anims.append(real_anim(*args, **kwargs))
        return anims[-1]

    patch = pytest.MonkeyPatch()
    patch.setattr(bayesgrasp.figures.files, "evolution_figure", kept)
    patch.setattr(bayesgrasp.figures.files, "plan_animation", kept_anim)
    try:
        files = write_figures(
            pb, option, tmp_path / "noisy", "Bayes", ("png",), frames_per_step=4, noise=noise
        )
        plain = write_figures(pb, option, tmp_path / "plain", "Bayes", ("png",), animation=False)
    finally:
        patch.undo()
    assert [f.name for f in files] == [*(p.name for p in plain), "plan.gif"]
    for name in ("part.png", "diameter.png", "transfer.png"):
        assert (tmp_path / "noisy" / name).read_bytes() == (tmp_path / "plain" / name).read_bytes()
    fig = figures["plan"]
    assert "exact under turn error normal:3 deg, contact asynchrony q=0.05" in fig.get_suptitle()
    assert f"P(success) = {option.success_probability:.3f}" in fig.get_suptitle()
    (caption,) = [t for t in anims[0].figure.texts if "P(success)" in t.get_text()]
    assert "exact under turn error normal:3 deg" in caption.get_text()
    last = fig.axes[-1]
    (stems,) = [c for c in last.collections if c.get_gid() == "distribution"]
    drawn = {round(float(s[0][0]), 6): float(s[1][1]) for s in stems.get_segments()}
    n = 100_000
    sim = simulate_kinematic(pb, option, n, noise, rng=5)
    for deg, count in zip(np.degrees(pb.states.stable), sim.observed, strict=True):
        exact = drawn.get(round(float(deg), 6), 0.0)
        sd = math.sqrt(max(exact * (1 - exact), 1e-6) / n)
        assert abs(count / n - exact) <= 4 * sd, (deg, count / n, exact)
