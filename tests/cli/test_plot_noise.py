"""``plot`` with ``--turn-noise``, ``--contact-noise`` and ``--payoff``.

``plot PART`` under the noise draws what ``plan PART --plot FILE`` draws with the same
options: the noise-aware Bayes plan's distributions after each step, exact under the noise,
with the noise in the title (compared panel by panel: ``plan --plot`` puts the part and its
diameter function above them). ``plot --sense`` under the noise draws, byte for byte, the
policy ``plan --sense --plot`` draws. A plan file drawn under the noise is checked against
sampled executions under that noise (:func:`~bayesgrasp.sim.kinematic.simulate_kinematic`).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from bayesgrasp.cli import main

pytest.importorskip("matplotlib")

NOISES = [
    ["--turn-noise", "normal:2"],
    ["--turn-noise", "uniform:3", "--contact-noise", "0.05"],
    ["--contact-noise", "0.1"],
]


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def refused(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    code, out, err = run(capsys, *args)
    assert code == 2 and out == "", (code, out, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


@pytest.fixture
def saved(monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    """Every figure saved during the test, by file name (the figure object)."""
    from matplotlib.figure import Figure

    figures: dict[str, Any] = {}
    real = Figure.savefig

    def savefig(self: Figure, fname: Any, *args: Any, **kwargs: Any) -> None:
        figures[Path(fname).name] = self
        real(self, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return figures


def panels(fig: Any) -> dict[str, Any]:
    """What an evolution figure (or the bottom of a plan figure) shows, panel by panel."""
    out: dict[str, Any] = {"title": fig.get_suptitle(), "panels": []}
    for ax in fig.axes:
        stems = [c for c in ax.collections if c.get_gid() == "distribution"]
        goal = [line.get_xdata()[0] for line in ax.lines if line.get_gid() == "goal"]
        segments = [np.asarray(s).tolist() for c in stems for s in c.get_segments()]
        labels = sorted(t.get_text() for t in ax.texts)
        out["panels"].append((ax.get_title(), segments, goal, labels))
    return out


def payoff_file(tmp_path: Path) -> Path:
    u = tmp_path / "u.csv"
    u.write_text("orientation_deg,value\n80.63,1\n260.63,0.5\n")
    return u


@pytest.mark.parametrize("noise", [*NOISES, ["--payoff", "PAYOFF"]], ids=" ".join)
def test_plot_draws_the_distributions_plan_plot_draws(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, saved: dict[str, Any], noise: list[str]
) -> None:
    noise = [str(payoff_file(tmp_path)) if x == "PAYOFF" else x for x in noise]
    figure = tmp_path / "plan-plot.png"
    code, _, _ = run(capsys, "plan", "key", *noise, "--plot", str(figure))
    assert code == 0
    folder = tmp_path / "figs"
    argv = ["plot", "key", *noise, "--out", str(folder), "--image-formats", "png"]
    code, out, err = run(capsys, *argv, "--no-animation")
    assert (code, err) == (0, "")
    names = ("part", "diameter", "transfer", "plan")
    assert out.split() == [str(folder / f"{n}.png") for n in names]
    assert all((folder / f"{n}.png").read_bytes()[:4] == b"\x89PNG" for n in names)
    mine, theirs = panels(saved["plan.png"]), panels(saved["plan-plot.png"].subfigs[1])
    assert mine == theirs
    assert "the distributions below: exact under " in mine["title"]
    assert ("E[cost] per unit payoff" in mine["title"]) == ("--payoff" in noise)
    if "--turn-noise" in noise:
        assert noise[noise.index("--turn-noise") + 1] in mine["title"]
    # the part's figures are the noise-free ones
    code, _, _ = run(capsys, "plot", "key", "--out", str(tmp_path / "plain"), "--no-animation")
    assert code == 0
    for name in ("part.png", "transfer.png"):
        assert (folder / name).read_bytes() == (tmp_path / "plain" / name).read_bytes()


def test_most_certain_under_noise_is_the_documents(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, saved: dict[str, Any]
) -> None:
    """``--plan most-certain``: the noise-aware most certain plan, its exact final distribution."""
    noise = ["--turn-noise", "normal:3"]
    code, text, _ = run(capsys, "plan", "key", *noise, "--json")
    assert code == 0
    doc = json.loads(text)
    mc = doc["most_certain"]
    argv = ["plot", "key", *noise, "--plan", "most-certain", "--out", str(tmp_path)]
    code, out, _ = run(capsys, *argv, "--image-formats", "svg", "--json")
    assert code == 0
    assert [Path(f).name for f in json.loads(out)["files"]][-2:] == ["plan.svg", "plan.gif"]
    shown = panels(saved["plan.svg"])
    option = doc["options"][mc]
    assert f"P(success) = {option['success_probability']:.3f}" in shown["title"]
    assert "the most certain plan" in shown["title"] and "normal:3 deg" in shown["title"]
    q = np.array(doc["noisy_options"][mc]["final_distribution"])
    tops = sorted(seg[1][1] for seg in shown["panels"][-1][1])
    np.testing.assert_allclose(tops, np.sort(q[q > 0]), atol=1e-12)
    assert len(shown["panels"]) == len(option["steps"]) + 1


def test_a_plan_file_under_noise_agrees_with_sampled_runs(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, saved: dict[str, Any]
) -> None:
    """A noise-free plan drawn under a 4 deg turn error: the exact figures against sampling.

    The last panel's stems and the title's P(success) (the plan's own goal) are the exact
    ones under the noise; 200,000 kinematic executions drawing the error agree within 4
    standard errors, and the title is the prediction ``simulate`` makes of the same plan.
    """
    from bayesgrasp import shapes
    from bayesgrasp.io.plans import read_plan
    from bayesgrasp.model.noise import NoiseModel, TurnNoise
    from bayesgrasp.model.problem import Problem
    from bayesgrasp.sim.kinematic import simulate_kinematic

    code, text, _ = run(capsys, "plan", "key", "--json")
    assert code == 0
    path = tmp_path / "key-plan.json"
    path.write_text(text)
    noise = ["--turn-noise", "normal:4"]
    argv = ["plot", "key", "--plan", str(path), *noise, "--out", str(tmp_path / "f")]
    assert run(capsys, *argv, "--image-formats", "png", "--no-animation")[0] == 0
    shown = panels(saved["plan.png"])
    stems = {round(seg[0][0], 6): seg[1][1] for seg in shown["panels"][-1][1]}
    pb = Problem.build(shapes.load("key"))
    option = read_plan(path).option
    model = NoiseModel(TurnNoise("normal", math.radians(4.0)))
    n = 200_000
    sim = simulate_kinematic(pb, option, n, model, rng=11)
    freq = sim.observed / n
    for deg, p in zip(np.degrees(pb.states.stable), freq, strict=True):
        exact = stems.get(round(float(deg), 6), 0.0)
        assert abs(p - exact) <= 4 * math.sqrt(max(exact * (1 - exact), 1e-6) / n), (deg, p, exact)
    success = float(freq[pb.success_states(option.final_orientation)].sum())
    title = shown["title"]
    drawn = float(title.split("P(success) = ")[1].split(",")[0])
    assert abs(success - drawn) <= 4 * math.sqrt(drawn * (1 - drawn) / n) + 5e-4
    assert f"the {path.name} plan" in title and "normal:4 deg" in title
    code, text, _ = run(capsys, "simulate", "key", "--plan", str(path), *noise, "--json")
    predicted = json.loads(text)["predicted_success"]
    assert f"P(success) = {predicted:.3f}" in title


def test_policy_under_noise_is_plan_sense_plot_byte_for_byte(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    sense = ["--sense", "width:0.5,0.1", "--max-actions", "2"]
    noise = ["--turn-noise", "normal:2", "--contact-noise", "0.05"]
    figure = tmp_path / "policy.png"
    assert run(capsys, "plan", "house", *sense, *noise, "--plot", str(figure))[0] == 0
    folder = tmp_path / "figs"
    argv = ["plot", "house", *sense, *noise, "--out", str(folder), "--image-formats", "png"]
    code, out, err = run(capsys, *argv)
    assert (code, out, err) == (0, f"{folder / 'policy.png'}\n", "")
    assert figure.read_bytes() == (folder / "policy.png").read_bytes()
    plain = tmp_path / "plain"
    argv = ["plot", "house", *sense, "--out", str(plain), "--image-formats", "png"]
    assert run(capsys, *argv)[0] == 0
    assert (plain / "policy.png").read_bytes() != figure.read_bytes()


def test_policy_with_a_payoff(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, saved: dict[str, Any]
) -> None:
    u = payoff_file(tmp_path)
    sense = ["--sense", "width:0.5,0.1", "--max-actions", "2", "--payoff", str(u)]
    figure = tmp_path / "policy.png"
    assert run(capsys, "plan", "key", *sense, "--plot", str(figure))[0] == 0
    argv = ["plot", "key", *sense, "--out", str(tmp_path / "f"), "--image-formats", "png"]
    assert run(capsys, *argv)[0] == 0
    assert (tmp_path / "f" / "policy.png").read_bytes() == figure.read_bytes()
    title = saved["policy.png"].axes[0].get_title()
    assert "per unit payoff (expected payoff " in title and " a cycle)" in title
    err = refused(capsys, *argv, "--also", "house", "--force")
    assert "a payoff is for one part" in err


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--turn-noise", "gauss:2"], "--turn-noise"),
        (["--turn-noise", "normal:2", "--method", "bfs"], "drop --method"),
        (["--contact-noise", "1.5"], "--contact-noise"),
        (["--payoff", "no-such-file.csv"], "no-such-file.csv"),
        (["--payoff", "BAD"], "payoff"),
        (["--sense", "width", "--turn-noise", "normal:"], "--turn-noise"),
    ],
)
def test_bad_noise_input_is_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, extra: list[str], match: str
) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("orientation_deg,value\n80.63,7\n")
    extra = [str(bad) if x == "BAD" else x for x in extra]
    out = tmp_path / "figs"
    err = refused(capsys, "plot", "key", *extra, "--out", str(out))
    assert match in err
    assert not out.exists()
