"""Parts near the largest coordinates the library takes (1e150) plan as their unit-size copies."""

from __future__ import annotations

import numpy as np
import pytest

from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import plan_exact

OUTLINE = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 0.8)])
HOLE = np.array([(0.2, 0.2), (0.2, 0.4), (0.4, 0.4), (0.4, 0.2)])


@pytest.mark.parametrize("scale", [9e149, 1e149, 1e-140])
@pytest.mark.parametrize("holes", [(), (HOLE,)])
def test_a_part_near_the_limits_is_its_unit_copy_scaled(
    scale: float, holes: tuple[np.ndarray, ...]
) -> None:
    unit = Part.from_outline(OUTLINE, holes)
    big = Part.from_outline(OUTLINE * scale, [h * scale for h in holes])
    np.testing.assert_allclose(big.center_of_mass / scale, unit.center_of_mass, rtol=1e-12)
    a, b = plan_exact(Problem.build(unit)), plan_exact(Problem.build(big))
    assert a.bayes_plan.success_probability == pytest.approx(b.bayes_plan.success_probability)
    assert [s.alpha for s in a.bayes_plan.steps] == pytest.approx(
        [s.alpha for s in b.bayes_plan.steps], abs=1e-9
    )
