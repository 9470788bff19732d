"""Public names of a package imported on first use (PEP 562), so light commands stay light.

``bayesgrasp --help`` and ``bayesgrasp plan --help`` need the action registry
(:mod:`bayesgrasp.model.actions`) but not numpy; a package ``__init__`` that imported every
module up front would load them all. A package lists where each name lives instead::

    __getattr__, __dir__ = lazy_names(__name__, {"Problem": "problem", "shapes": ""})

(``""``: the name is the package's own submodule). Static type checkers read the same names
from an ``if TYPE_CHECKING:`` block of imports.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["lazy_names"]


def lazy_names(
    package: str, where: Mapping[str, str]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The module ``__getattr__`` and ``__dir__`` of ``package``.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    where : mapping of str to str
        Each public name and the submodule (relative to ``package``) that defines it; ``""``
        for a name that is itself a submodule.

    Returns
    -------
    (__getattr__, __dir__)
        ``__getattr__`` imports the submodule, stores the value in the package (the next
        lookup costs nothing) and returns it; any other name is an ``AttributeError``.
        ``__dir__`` lists the package's ``__all__`` (else the lazy names).

    Examples
    --------
    >>> import bayesgrasp.model as model  # its __init__ uses lazy_names
    >>> model.Problem.__module__, "Problem" in dir(model)
    ('bayesgrasp.model.problem', True)
    >>> model.nothing
    Traceback (most recent call last):
    ...
    AttributeError: module 'bayesgrasp.model' has no attribute 'nothing'
    """

    def __getattr__(name: str) -> Any:
        module = where.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        if module == "":
            value = importlib.import_module(f"{package}.{name}")
        else:
            value = getattr(importlib.import_module(f"{package}.{module}"), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(getattr(sys.modules[package], "__all__", where))

    return __getattr__, __dir__
