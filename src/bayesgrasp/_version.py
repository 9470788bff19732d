"""The package's version: the ``version`` of ``pyproject.toml``, the one place it is kept.

It is read from the installed distribution's metadata when first asked for
(``bayesgrasp.__version__``), so that importing the package does not pay for
:mod:`importlib.metadata` (about 20-50 ms) on every command line.

Examples
--------
>>> import bayesgrasp
>>> bayesgrasp.__version__ == version("bayesgrasp")
True
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

__all__ = ["__version__"]

try:
    __version__: str = version("bayesgrasp")
except PackageNotFoundError:  # pragma: no cover - a source tree that was never installed
    __version__ = "0+unknown"
