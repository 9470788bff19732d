"""The catalogue of familiar parts from the seed's Table 1, as data files.

Each part is a JSON file beside this module: ``{"name", "description", "vertices",
"units"}``. The seed prints no coordinates; the outlines are designed to be recognisable with
the stated side counts, and documented in each file's ``description``.
"""

from __future__ import annotations

import json
from functools import cache
from importlib import resources

from ..errors import PartError
from ..geometry import Part

__all__ = ["describe", "load", "names"]


@cache
def _data() -> dict[str, dict[str, object]]:
    out = {}
    for entry in resources.files(__package__).iterdir():
        if entry.name.endswith(".json"):
            data = json.loads(entry.read_text(encoding="utf-8"))
            out[data["name"]] = data
    return out


def names() -> list[str]:
    """Names of the catalogue parts, in the order of the seed's Table 1."""
    data = _data()
    return sorted(data, key=lambda n: (int(str(data[n].get("order", 99))), n))


def describe(name: str) -> str:
    """The documented design of a catalogue part."""
    return str(_data()[name].get("description", ""))


def load(name: str) -> Part:
    """Load a catalogue part by name.

    Examples
    --------
    >>> load("triangle").hull.n_sides
    3
    """
    data = _data()
    if name not in data:
        raise PartError(f"no catalogue part {name!r}; expected one of {', '.join(names())}")
    d = data[name]
    return Part.from_points(d["vertices"], name=name, units=d.get("units"))  # type: ignore[arg-type]
