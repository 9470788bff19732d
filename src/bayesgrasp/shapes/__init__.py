"""The catalogue of familiar parts from the seed's Table 1, as data files.

Each part is a JSON file beside this module::

    {"name": "house", "order": 4, "units": "mm",
     "description": "...how the outline was designed...",
     "vertices": [[x, y], ...]}

``vertices`` is the part's *outline* in order (a simple polygon, possibly non-convex: a tuning
fork, a hand). The gripper only ever touches the convex hull (the seed, section 4.1,
assumption 3), so the loader builds the :class:`~bayesgrasp.geometry.polygon.Part` from the outline
and the hull is computed; the side counts of Table 1 are side counts of the hull. The centre
of mass is the area centroid of the outline (a plate of uniform thickness), not of the hull:
the two differ for non-convex parts, and pushing depends on it.

The seed prints no coordinates. The outlines are designed to be recognisable with the stated
side counts and fitted so that the exact planner comes close to the printed rows; each file's
``description`` says how (see ``benchmarks/fit_catalogue.py`` and :mod:`bayesgrasp.paper.table1`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache
from importlib import resources
from typing import TYPE_CHECKING

from ..errors import PartError

if TYPE_CHECKING:  # pragma: no cover
    from ..geometry.polygon import Part

__all__ = ["CatalogueEntry", "describe", "entry", "load", "names"]

_KEYS = ("name", "order", "units", "description", "vertices")


@dataclass(frozen=True, slots=True)
class CatalogueEntry:
    """One catalogue data file, as stored.

    Attributes
    ----------
    name : str
        The catalogue name (what ``bayesgrasp squeeze NAME`` takes).
    order : int
        Position in the seed's Table 1 (1 = first row).
    units : str
        Units of the coordinates.
    description : str
        How the outline was designed and what it reproduces.
    vertices : tuple of (float, float)
        The outline, in order (may be non-convex).
    """

    name: str
    order: int
    units: str
    description: str
    vertices: tuple[tuple[float, float], ...]


def _parse(filename: str, text: str) -> CatalogueEntry:
    """Validate one data file (a broken file is a packaging bug, reported clearly)."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise PartError(f"catalogue file {filename!r} is not valid JSON: {exc}") from None
    if not isinstance(data, dict) or any(k not in data for k in _KEYS):
        raise PartError(
            f"catalogue file {filename!r} must be an object with keys {', '.join(_KEYS)}; "
            f"got {sorted(data) if isinstance(data, dict) else type(data).__name__}"
        )
    from ..geometry.polygon import as_points

    pts = as_points(data["vertices"], f"vertices of catalogue part {data['name']!r}")
    return CatalogueEntry(
        str(data["name"]),
        int(data["order"]),
        str(data["units"]),
        str(data["description"]),
        tuple((float(x), float(y)) for x, y in pts),
    )


@cache
def _entries() -> dict[str, CatalogueEntry]:
    out: dict[str, CatalogueEntry] = {}
    for item in resources.files(__package__).iterdir():
        if item.name.endswith(".json"):
            e = _parse(item.name, item.read_text(encoding="utf-8"))
            out[e.name] = e
    return dict(sorted(out.items(), key=lambda kv: (kv[1].order, kv[0])))


def names() -> list[str]:
    """Names of the catalogue parts, in the order of the seed's Table 1.

    Returns
    -------
    list of str

    Examples
    --------
    >>> names()[:3]
    ['triangle', 'rectangle', 'ic-chip']
    """
    return list(_index())


@cache
def _index() -> dict[str, int]:
    """Name and Table-1 position of each data file, read without validating the outlines.

    ``--help`` lists the names: this keeps numpy out of it (a broken file is still reported
    by :func:`entry` and :func:`load`).
    """
    out: dict[str, int] = {}
    for item in resources.files(__package__).iterdir():
        if item.name.endswith(".json"):
            try:
                data = json.loads(item.read_text(encoding="utf-8"))
                out[str(data["name"])] = int(data["order"])
            except (ValueError, KeyError, TypeError):
                out[item.name.removesuffix(".json")] = 10**9
    return dict(sorted(out.items(), key=lambda kv: (kv[1], kv[0])))


def entry(name: str) -> CatalogueEntry:
    """The stored data of a catalogue part.

    Parameters
    ----------
    name : str
        A name from :func:`names`.

    Returns
    -------
    CatalogueEntry

    Raises
    ------
    PartError
        If there is no such catalogue part.

    Examples
    --------
    >>> entry("rectangle").vertices
    ((0.0, 0.0), (31.0, 0.0), (31.0, 20.0), (0.0, 20.0))
    """
    data = _entries()
    if name not in data:
        raise PartError(
            f"no catalogue part {name!r}; expected one of {', '.join(data)}"
            if isinstance(name, str)
            else f"a catalogue part name must be a string; got {type(name).__name__}"
        )
    return data[name]


def describe(name: str) -> str:
    """The documented design of a catalogue part.

    Parameters
    ----------
    name : str
        A name from :func:`names`.

    Returns
    -------
    str

    Raises
    ------
    PartError
        If there is no such catalogue part.

    Examples
    --------
    >>> describe("rectangle")[:16]
    'A 31 x 20 mm rec'
    """
    return entry(name).description


def load(name: str) -> Part:
    """Load a catalogue part by name.

    The part's hull is the convex hull of the stored outline; its centre of mass is the
    outline's area centroid.

    Parameters
    ----------
    name : str
        A name from :func:`names`.

    Returns
    -------
    Part

    Raises
    ------
    PartError
        If there is no such catalogue part.

    Examples
    --------
    >>> load("triangle").hull.n_sides
    3
    >>> load("tuning-fork").outline.shape[0] > load("tuning-fork").hull.n_sides
    True
    """
    e = entry(name)
    import numpy as np

    from ..geometry.polygon import Part, polygon_area_centroid

    outline = np.array(e.vertices, dtype=np.float64)
    _, com = polygon_area_centroid(outline)
    return Part.from_points(outline, name=e.name, center_of_mass=com, units=e.units)
