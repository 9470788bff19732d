"""``plan --plot FILE`` and ``--export FILE`` for one part or many: file name templates.

With several parts (more PARTs or ``--batch``) each part gets its own files: the path is a
template in which ``{name}`` is the part's name (and ``{index}``, if present, its place in
the run: 1 for the first part). A path without ``{name}`` is refused with several parts
(every part would write the same file). With one part a template is filled the same way.

Every file is checked before it is written, as a single ``plan`` run checks: a file that
exists is replaced only with ``--force``, an input of the run (the part file, the prior's
file, the batch file) never; a file written earlier in the same run (two parts of the same
name) is refused. A part whose file is refused, or cannot be written, gets an error line
(exit code 2) instead of its document; the other parts go on.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import typer

from .common import IMAGE_FORMATS, check_outputs, save_figure

__all__ = ["NAME", "PartOutputs", "safe_name"]

NAME = "{name}"
INDEX = "{index}"
_UNSAFE = re.compile(r"[^A-Za-z0-9_.+-]+")


def safe_name(name: str) -> str:
    """A part's name as a file name: letters, digits and ``_.+-`` (others become ``_``).

    Examples
    --------
    >>> safe_name("key"), safe_name("my part/v2"), safe_name("..")
    ('key', 'my_part_v2', 'part')
    """
    out = _UNSAFE.sub("_", name).strip("_")
    return "part" if out.strip(".") == "" else out


@dataclass
class PartOutputs:
    """The ``--plot`` and ``--export`` files of a ``plan`` run, one pair a part.

    Build with :meth:`of`, which refuses bad paths before any work (exit 2).
    """

    plot: Path | None
    export: Path | None
    force: bool
    inputs: tuple[Path, ...]
    written: set[Path] = field(default_factory=set)

    @classmethod
    def of(
        cls,
        plot: Path | None,
        export: Path | None,
        force: bool,
        inputs: Iterable[Path],
        several: bool,
    ) -> PartOutputs | None:
        """The outputs of the options (``None`` when neither is given), checked.

        ``several``: the run plans more than one part, so each path must hold ``{name}``.

        Raises
        ------
        typer.BadParameter
            A path without ``{name}`` for several parts, a file name of the wrong kind, or
            a folder (without ``{name}`` in it) that does not exist.
        """
        if plot is None and export is None:
            return None
        kinds = (("--plot", plot, IMAGE_FORMATS), ("--export", export, ("csv", "json")))
        for hint, path, formats in kinds:
            if path is None:
                continue
            text = str(path)
            if several and NAME not in text:
                raise typer.BadParameter(
                    f"several parts need one file each: give a path with {NAME} (the "
                    f"part's name), such as 'out/{NAME}.{formats[0]}'; got {text!r}",
                    param_hint=hint,
                )
            suffix = path.suffix.lstrip(".").lower()
            if suffix not in formats:
                what = "figure" if hint == "--plot" else "robot"
                ends = ", ".join(f".{f}" for f in formats[:-1]) + f" or .{formats[-1]}"
                raise typer.BadParameter(
                    f"the {what} file must end in {ends}; got {path.name!r}", param_hint=hint
                )
            folder = path.parent
            if NAME not in str(folder) and INDEX not in str(folder) and not folder.is_dir():
                raise typer.BadParameter(
                    f"no folder {str(folder)!r} to write into", param_hint=hint
                )
        return cls(plot, export, force, tuple(inputs))

    def paths(self, name: str, index: int) -> tuple[Path | None, Path | None]:
        """The plot and export files of a part (the templates filled)."""

        def fill(path: Path | None) -> Path | None:
            if path is None:
                return None
            text = str(path).replace(NAME, safe_name(name)).replace(INDEX, str(index))
            return Path(text)

        return fill(self.plot), fill(self.export)

    def check(self, name: str, index: int, inputs: Iterable[Path] = ()) -> None:
        """Refuse a part's files before they are written (``inputs``: the part's own files).

        Raises
        ------
        typer.BadParameter
            A file that exists (without ``force``), is an input, was written for an earlier
            part of this run, or whose folder does not exist.
        """
        given = [*self.inputs, *inputs]
        for hint, path in zip(("--plot", "--export"), self.paths(name, index), strict=True):
            if path is None:
                continue
            if path in self.written:
                raise typer.BadParameter(
                    f"{str(path)!r} was written for an earlier part of this run (two parts "
                    f"named {name!r}); name the parts apart or add {INDEX} to the path",
                    param_hint=hint,
                )
            if not path.parent.is_dir():
                raise typer.BadParameter(
                    f"no folder {str(path.parent)!r} to write into", param_hint=hint
                )
            check_outputs([path], given, self.force, hint)

    def write(
        self,
        name: str,
        index: int,
        figure: Callable[[], Any],
        robot: Callable[[Path], None],
    ) -> list[Path]:
        """Write a part's files: ``figure()`` makes its figure, ``robot(path)`` its robot file.

        Call :meth:`check` first. Returns the files written (each also said on stderr).

        Raises
        ------
        typer.BadParameter
            A file that cannot be written.
        """
        plot, export = self.paths(name, index)
        out = []
        if plot is not None:
            save_figure(figure(), plot)
            out.append(plot)
        if export is not None:
            robot(export)
            out.append(export)
        for path in out:
            self.written.add(path)
            typer.echo(f"bayesgrasp: wrote {path}", err=True)
        return out
