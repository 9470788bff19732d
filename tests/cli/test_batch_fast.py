"""``plan --batch`` without typer (issue 12): the batch's own parser against typer's.

:func:`bayesgrasp.cli.batch.parse_batch_args` must give, for every argument list it accepts,
the batch file, problem spec and flags that typer's ``plan`` passes to ``run_batch``; what it
does not accept goes to typer. The whole command then writes the same bytes either way.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bayesgrasp.cli import batch as batch_module
from bayesgrasp.cli import main
from bayesgrasp.cli.specs import PartSpec


def typer_call(args: list[str], monkeypatch: pytest.MonkeyPatch) -> tuple[Any, ...] | None:
    """What typer's ``plan`` passes to ``run_batch`` (None: it stopped before, an error)."""
    seen: list[tuple[Any, ...]] = []

    def record(*call: Any) -> int:
        seen.append(call)
        return 0

    with monkeypatch.context() as m:
        m.setattr(batch_module, "fast_main", lambda args: None)
        m.setattr(batch_module, "run_batch", record)
        main(args)
    return seen[0] if seen else None


ACCEPTED = [
    ["plan", "--batch", "parts.jsonl"],
    ["plan", "--batch=parts.jsonl", "--json"],
    ["plan", "--batch", "-", "--goal", "symmetry", "--prior", "vonmises:30,2"],
    ["plan", "--only", "best", "--guaranteed", "--batch", "a b.jsonl", "--method", "bfs"],
    ["plan", "--batch", "p.jsonl", "--squeeze-cost", "2", "--verify-cost=0.5"],
    ["plan", "--batch", "p.jsonl", "--first-squeeze-cost", "3e1", "--retry-cost", "0.25"],
    ["plan", "--batch", "p.jsonl", "--actions", "squeeze,push-grasp", "--push-grasp-cost", "7"],
    ["plan", "--batch", "p.jsonl", "--accuracy", "89.99", "--max-squeezes", "2"],
    ["plan", "--batch", "./x//p.jsonl", "--first-push-grasp-cost", "0", "--prior", "uniform"],
]
HANDED_TO_TYPER = [
    ["plan", "--batch"],
    ["plan", "house", "--batch", "p.jsonl"],
    ["plan", "--batch", "p.jsonl", "--help"],
    ["plan", "--batch", "p.jsonl", "--com", "1,2"],
    ["plan", "--batch", "p.jsonl", "--goal", "SINGLE"],
    ["plan", "--batch", "p.jsonl", "--accuracy", "90"],
    ["plan", "--batch", "p.jsonl", "--accuracy", "-1"],
    ["plan", "--batch", "p.jsonl", "--squeeze-cost", "nan"],
    ["plan", "--batch", "p.jsonl", "--squeeze-cost", "1e300"],
    ["plan", "--batch", "p.jsonl", "--max-squeezes", "0"],
    ["plan", "--batch", "p.jsonl", "--goal", "single", "--goal", "symmetry"],
    ["plan", "--batch", "p.jsonl", "--json=1"],
    ["plan", "--batch", "p.jsonl", "--prior", "--goal"],
    ["plan", "--batch", "p.jsonl", "--sense", "width"],
    ["squeeze", "--batch", "p.jsonl"],
]


@pytest.mark.parametrize("args", ACCEPTED, ids=" ".join)
def test_accepted_arguments_give_typers_call(
    args: list[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    parsed = batch_module.parse_batch_args(args)
    assert parsed is not None
    batch, spec, guaranteed, best_only = parsed
    assert typer_call(args, monkeypatch) == (
        PartSpec(None),  # type: ignore[arg-type]
        [],
        batch,
        spec,
        guaranteed,
        best_only,
    )


@pytest.mark.parametrize("args", HANDED_TO_TYPER, ids=" ".join)
def test_other_arguments_go_to_typer(args: list[str]) -> None:
    assert batch_module.parse_batch_args(args) is None


# Options and values, typer's readings of which must match wherever the parser accepts them:
# mostly values the parser accepts, and some it must leave to typer.
_NUMBERS = ["0", "1", "2.5", "01", "007.50", "1e3", "1E-2", "3", "89.99", "1e-7", "12.000"]
_ODD = ["1.", ".5", "1e400", "-1", "nan", "inf", "90", "95", "1_0", " 1", "0x1", "", "-"]
_CHOICES = {
    "--goal": ["single", "symmetry"],
    "--method": ["exact", "bfs"],
    "--only": ["all", "best"],
}
_TEXTS = {
    "--batch": ["p.jsonl", "-", "a b/c.jsonl", "./x//y.jsonl"],
    "--prior": ["uniform", "vonmises:1,2", "histogram:h.csv", "x=y"],
    "--actions": ["squeeze", "push-grasp", "squeeze,push-grasp", " squeeze , ", ",,"],
    "--max-squeezes": ["1", "2", "12", "0", "01"],
}
_COSTS = ["--accuracy", "--squeeze-cost", "--push-grasp-cost", "--verify-cost", "--retry-cost"]
_COSTS += ["--first-squeeze-cost", "--first-push-grasp-cost"]
_POOLS = {
    **{k: st.sampled_from(v) for k, v in {**_CHOICES, **_TEXTS}.items()},
    **{k: st.sampled_from(_NUMBERS) for k in _COSTS},
}
_ODD_VALUE = st.sampled_from([*_ODD, "SINGLE", "best "])


@st.composite
def _arguments(draw: st.DrawFn) -> list[str]:
    names = draw(st.lists(st.sampled_from(sorted(_POOLS)), unique=True, max_size=6))
    if draw(st.booleans()):
        names = [*dict.fromkeys(["--batch", *names])]
    args = ["plan"]
    for name in draw(st.permutations(names)):
        odd = draw(st.integers(0, 9)) == 0
        value = draw(_ODD_VALUE if odd else _POOLS[name])
        args += [f"{name}={value}"] if draw(st.booleans()) else [name, value]
    return args + draw(st.lists(st.sampled_from(["--guaranteed", "--json"]), unique=True))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_arguments())
def test_any_accepted_arguments_give_typers_call(args: list[str]) -> None:
    parsed = batch_module.parse_batch_args(args)
    if parsed is None:
        return
    with pytest.MonkeyPatch.context() as mp:
        assert typer_call(args, mp) == (PartSpec(None), [], *parsed)  # type: ignore[arg-type]


def test_the_comparison_sees_a_different_spec(monkeypatch: pytest.MonkeyPatch) -> None:
    """A parser that read a value otherwise is caught: the test above can fail."""
    import dataclasses

    args = ["plan", "--batch", "p.jsonl", "--verify-cost", "2"]
    batch, spec, *flags = batch_module.parse_batch_args(args)  # type: ignore[misc]
    wrong = dataclasses.replace(spec, verify=2.5)
    assert typer_call(args, monkeypatch) != (PartSpec(None), [], batch, wrong, *flags)  # type: ignore[arg-type]


OPTION_SETS = [
    [],
    ["--goal", "symmetry", "--accuracy", "2"],
    ["--prior", "vonmises:30,2", "--squeeze-cost", "2", "--first-squeeze-cost", "3"],
    ["--actions", "squeeze,push-grasp", "--guaranteed", "--only", "best"],
    ["--method", "bfs", "--max-squeezes", "2"],
    ["--prior", "vonmises:30,bad"],  # every line fails
]


@pytest.mark.parametrize("options", OPTION_SETS, ids=lambda o: " ".join(o) or "default")
def test_the_same_bytes_with_and_without_typer(
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    options: list[str],
) -> None:
    rows = [
        json.dumps("house"),
        '{"name": "sq", "vertices": [[0, 0], [2, 0], [2, 1], [0, 1]]}',
        "not json",
        '{"vertices": [[0, 0], [1, 0], [2, 0]]}',
        '{"vertices": [[0, 0], [3, 0], [1, 2]], "units": "mm"}',
    ]
    batch = tmp_path / "parts.jsonl"
    batch.write_text("\n".join(rows) + "\n")
    args = ["plan", "--batch", str(batch), *options]
    assert batch_module.parse_batch_args(args) is not None
    fast = main(args), capsys.readouterr()
    with monkeypatch.context() as m:
        m.setattr(batch_module, "fast_main", lambda args: None)
        slow = main(args), capsys.readouterr()
    assert fast == slow
    assert fast[0] == 2 and fast[1].out.count("\n") == 5


def test_an_unreadable_batch_file_is_typers_usage_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    args = ["plan", "--batch", str(tmp_path / "missing.jsonl")]
    assert batch_module.parse_batch_args(args) is not None
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "cannot read" in err and "--batch" in err and err.count("\n") == 1


def test_a_plan_loaded_with_other_action_kinds_goes_to_typer(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import bayesgrasp.cli.options as options

    args = ["plan", "--batch", "p.jsonl"]
    monkeypatch.setitem(options.COST_KINDS, "bayesgrasp.cli.plan.plan", ("squeeze",))
    assert batch_module.parse_batch_args(args) is None


def test_a_batch_imports_neither_typer_nor_pydantic(tmp_path: Path) -> None:
    batch = tmp_path / "parts.jsonl"
    batch.write_text('"house"\n{"vertices": [[0, 0], [2, 0], [2, 1], [0, 1]]}\n')
    probe = (
        "import sys, contextlib, io\n"
        "from bayesgrasp.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    code = main(sys.argv[1:])\n"
        "print(code)\n"
        "print(sorted(m for m in sys.modules if m.startswith(('typer', 'click', 'pydantic',"
        " 'bayesgrasp.cli.', 'bayesgrasp.report'))))\n"
    )
    run = [sys.executable, "-c", probe, "plan", "--batch", str(batch), "--goal", "symmetry"]
    proc = subprocess.run(run, capture_output=True, text=True, check=True)
    code, modules = proc.stdout.splitlines()[-2:]
    assert code == "0", proc.stderr
    assert json.loads(modules.replace("'", '"')) == ["bayesgrasp.cli.batch", "bayesgrasp.cli.specs"]
    # the probe can fail: PART arguments take typer's path
    run = [sys.executable, "-c", probe, "plan", "house", "--batch", str(batch)]
    proc = subprocess.run(run, capture_output=True, text=True, check=True)
    assert "typer" in proc.stdout.splitlines()[-1]
