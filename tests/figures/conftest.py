"""Shared parts, problems and helpers of the figure tests.

Artists are found by their ``gid``; overlaps are measured on the drawn canvas.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from bayesgrasp.io import read_part
from bayesgrasp.model.problem import Problem

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def artists_by_gid(ax: Any, gid: str) -> list[Any]:
    """The lines, patches, collections and texts of ``ax`` whose gid is ``gid``."""
    artists = [*ax.lines, *ax.patches, *ax.collections, *ax.texts]
    return [a for a in artists if a.get_gid() == gid]


@pytest.fixture
def by_gid() -> Callable[[Any, str], list[Any]]:
    """``by_gid(ax, gid)``: the artists of ``ax`` with that gid."""
    return artists_by_gid


@pytest.fixture(scope="session")
def bracket_problem() -> Problem:
    return Problem.build(read_part(EXAMPLES / "bracket.dxf"))


@pytest.fixture(scope="session")
def peanut_problem() -> Problem:
    """Stable orientations 5 degrees apart (labels that would overlap) and push-grasps."""
    return Problem.build(read_part(EXAMPLES / "peanut.svg"), actions="squeeze,push-grasp")
