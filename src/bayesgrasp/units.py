"""Length units: the names bayesgrasp knows, and conversion between them.

A part's coordinates are in its file's units (:attr:`~bayesgrasp.geometry.Part.units`), or
in none when the file does not say. The names are a fixed list: the units of mechanical
drawings (``um``, ``mm``, ``cm``, ``m``, ``in``, ``ft``), CSS pixels (``px``, SVG user units:
1/96 in) and every length a DXF header can name (``$INSUNITS``). A name outside the list is
refused, never guessed. Parts are never converted silently: :func:`convert` does it when
asked (recognition converts each candidate part to the first one's units).

Examples
--------
>>> unit_name("millimetres"), unit_name(None)
('mm', None)
>>> factor("in", "mm")
25.4
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .errors import PartError

if TYPE_CHECKING:  # pragma: no cover
    from .geometry.polygon import Part

__all__ = ["LENGTHS", "PRIMARY", "convert", "factor", "unit_name"]

#: Metres per unit of every unit name bayesgrasp knows.
LENGTHS: dict[str, float] = {
    "um": 1e-6,
    "mm": 1e-3,
    "cm": 1e-2,
    "m": 1.0,
    "in": 0.0254,
    "ft": 0.3048,
    "px": 0.0254 / 96,  # CSS pixel: SVG user units
    # The rest of what a DXF header names ($INSUNITS).
    "nm": 1e-9,
    "Å": 1e-10,
    "dm": 0.1,
    "dam": 10.0,
    "hm": 100.0,
    "km": 1000.0,
    "Gm": 1e9,
    "µin": 0.0254e-6,
    "mil": 0.0254e-3,
    "yd": 0.9144,
    "mi": 1609.344,
    "au": 149_597_870_700.0,
    "ly": 9_460_730_472_580_800.0,
    "pc": 3.0856775814913673e16,
    "US ft": 1200 / 3937,
    "US in": 100 / 3937,
    "US yd": 3600 / 3937,
    "US mi": 6_336_000 / 3937,
}

#: The units of mechanical drawings, named in messages.
PRIMARY = ("mm", "cm", "m", "in", "ft", "um")

_ALIASES = {
    "µm": "um",
    "μm": "um",
    "micron": "um",
    "microns": "um",
    "micrometre": "um",
    "micrometer": "um",
    "micrometres": "um",
    "micrometers": "um",
    "millimetre": "mm",
    "millimeter": "mm",
    "millimetres": "mm",
    "millimeters": "mm",
    "centimetre": "cm",
    "centimeter": "cm",
    "centimetres": "cm",
    "centimeters": "cm",
    "metre": "m",
    "meter": "m",
    "metres": "m",
    "meters": "m",
    "inch": "in",
    "inches": "in",
    "foot": "ft",
    "feet": "ft",
}


def unit_name(units: object) -> str | None:
    """The canonical name of a unit (``None``: no units), or a :class:`PartError`.

    Case and surrounding spaces do not matter for the common names (``"MM"``, ``" Inch"``).

    Examples
    --------
    >>> unit_name("Inches"), unit_name("mil")
    ('in', 'mil')
    >>> unit_name("furlong")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bayesgrasp.errors.PartError: unknown units 'furlong'; use one of mm, cm, m, in, ft, um ...
    """
    if units is None:
        return None
    if not isinstance(units, str):
        raise PartError(f"units must be a name such as 'mm'; got {units!r}")
    if units in LENGTHS:
        return units
    key = units.strip()
    low = key.lower()
    for name in (key, low, _ALIASES.get(low)):
        if name is not None and name in LENGTHS:
            return name
    raise PartError(
        f"unknown units {units!r}; use one of {', '.join(PRIMARY)} "
        "(or px, or a DXF unit such as mil or yd)"
    )


def factor(src: str, dst: str) -> float:
    """How many ``dst`` make one ``src`` (multiply coordinates in ``src`` by it).

    Examples
    --------
    >>> factor("mm", "mm"), round(factor("ft", "in"), 12)
    (1.0, 12.0)
    """
    a, b = unit_name(src), unit_name(dst)
    if a is None or b is None:
        raise PartError("a conversion needs both units")
    if a == b:
        return 1.0
    return LENGTHS[a] / LENGTHS[b]


def convert(part: Part, units: str) -> Part:
    """The part with its coordinates (outline, holes, centre of mass) in ``units``.

    Raises
    ------
    PartError
        The part has no units (nothing says what its numbers are), or is curved (its exact
        model is converted by saving the drawing in ``units``).

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> p = convert(Part.from_points([(0, 0), (1, 0), (0, 1)], units="in"), "mm")
    >>> p.units, float(p.hull.vertices.max())
    ('mm', 25.4)
    """
    target = unit_name(units)
    if target is None:
        raise PartError("give the units to convert to")
    if part.units is None:
        raise PartError(
            f"part {part.name!r} has no units, so it cannot be converted to {target}: give "
            "its units in the file"
        )
    if part.units == target:
        return part
    return part.scaled(factor(part.units, target), target)
