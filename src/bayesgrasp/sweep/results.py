"""Results files of a sweep: Parquet (a folder of batch files) or CSV, appended in batches.

A sweep writes its rows in batches as they come, so that a crash keeps every finished
batch:

- **Parquet**: ``RESULTS`` is a folder (a Parquet *dataset*, which ``pandas.read_parquet``,
  ``pyarrow.parquet.read_table``, DuckDB and Spark read as one table) of files
  ``part-NNNNNN.parquet``, one a batch, each written under a temporary name and renamed
  when complete, so that no reader ever sees half a file. Every file's schema metadata
  holds the run's metadata under the key ``bayesgrasp.sweep``; ``_sweep.json`` in the
  folder lists the metadata of every run that wrote into it.
- **CSV**: ``RESULTS`` is one file with a header row, appended and flushed a batch at a
  time; a last line cut by a crash is dropped when the sweep is resumed. The runs'
  metadata is in ``RESULTS.meta.json`` beside it (CSV has no place for it).

The metadata of a run (schema ``bayesgrasp.sweep/1``): the options (and their key), the
seed, the package version, the Python and Dask versions, the start time.

Resuming reads the rows already there and skips each part whose path, hash and options
already have a row; an existing file is never replaced unless ``force`` is given.
"""

from __future__ import annotations

import csv
import datetime
import io
import json
import logging
import os
import platform
import shutil
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any, Literal, Protocol

from ..errors import MissingExtraError
from .options import SweepError, SweepOptions
from .rows import ROW_COLUMNS

__all__ = [
    "FORMATS",
    "METADATA_KEY",
    "SCHEMA",
    "CsvWriter",
    "ParquetWriter",
    "ResultsWriter",
    "open_results",
    "read_metadata",
    "read_results",
    "results_format",
    "run_metadata",
]

logger = logging.getLogger(__name__)

#: Formats of results files.
FORMATS = ("parquet", "csv")
#: Schema name of a run's metadata.
SCHEMA = "bayesgrasp.sweep/1"
#: Key of the run's metadata in each Parquet file's schema metadata.
METADATA_KEY = b"bayesgrasp.sweep"
Format = Literal["parquet", "csv"]
Key = tuple[str, str, str]  # (path, sha256, options_key)


def _pyarrow() -> Any:
    try:
        import pyarrow as pa
        import pyarrow.parquet  # registers pa.parquet
    except ImportError:
        raise MissingExtraError("pyarrow", "sweep") from None
    return pa


def run_metadata(options: SweepOptions) -> dict[str, Any]:
    """The metadata of a run: options, seed, versions, start time.

    Examples
    --------
    >>> run_metadata(SweepOptions(seed=3))["seed"]
    3
    """
    from importlib.metadata import PackageNotFoundError, version

    try:
        dask_version: str | None = version("distributed")
    except PackageNotFoundError:
        dask_version = None
    from .. import __version__

    return {
        "schema": SCHEMA,
        "bayesgrasp_version": __version__,
        "python_version": platform.python_version(),
        "dask_version": dask_version,
        "options": options.to_json(),
        "options_key": options.key,
        "seed": options.seed,
        "started": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
    }


def results_format(out: Path, fmt: str | None = None) -> Format:
    """The format of a results path: given, or a folder / ``.parquet`` (Parquet), ``.csv``."""
    if fmt is not None:
        if fmt not in FORMATS:
            raise SweepError(f"`fmt` must be one of {', '.join(FORMATS)}; got {fmt!r}")
        return "csv" if fmt == "csv" else "parquet"
    if out.is_dir() or out.suffix.lower() == ".parquet":
        return "parquet"
    if out.suffix.lower() == ".csv":
        return "csv"
    raise SweepError(f"{out}: cannot tell the results format; give fmt='parquet' or 'csv'")


def _key(row: dict[str, Any]) -> Key:
    return (str(row["path"]), str(row["sha256"] or ""), str(row["options_key"]))


class ResultsWriter(Protocol):
    """Appends rows to a results file."""

    path: Path

    def done_keys(self) -> set[Key]:
        """``(path, sha256, options_key)`` of every row already in the file."""
        ...

    def write(self, rows: Sequence[dict[str, Any]]) -> None:
        """Append a batch of rows (durable when this returns)."""
        ...


def _arrow_schema(meta: dict[str, Any]) -> Any:
    pa = _pyarrow()
    types = {str: pa.string(), int: pa.int64(), float: pa.float64(), bool: pa.bool_()}
    fields = [pa.field(name, types[t]) for name, t in ROW_COLUMNS]
    return pa.schema(fields, metadata={METADATA_KEY: json.dumps(meta).encode()})


def _append_run(path: Path, meta: dict[str, Any]) -> None:
    """Add a run's metadata to a JSON sidecar ``{"runs": [...]}``."""
    runs = json.loads(path.read_text(encoding="utf-8"))["runs"] if path.exists() else []
    runs.append(meta)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps({"schema": SCHEMA, "runs": runs}, indent=1), encoding="utf-8")
    os.replace(tmp, path)


class ParquetWriter:
    """A folder of Parquet files, one a batch (see the module's notes)."""

    def __init__(self, path: Path, meta: dict[str, Any]) -> None:
        self.path = path
        self.schema = _arrow_schema(meta)
        path.mkdir(parents=True, exist_ok=True)
        for stale in path.glob(".part-*.tmp"):  # a batch a crash cut short
            stale.unlink()
        numbers = [int(f.stem.split("-")[1]) for f in path.glob("part-*.parquet")]
        self.next = max(numbers, default=-1) + 1
        _append_run(path / "_sweep.json", meta)

    def done_keys(self) -> set[Key]:
        """``(path, sha256, options_key)`` of every row already in the folder."""
        return {_key(r) for r in read_results(self.path, "parquet")}

    def write(self, rows: Sequence[dict[str, Any]]) -> None:
        """Write one batch file (under a temporary name, renamed when complete)."""
        if not rows:
            return
        pa = _pyarrow()
        table = pa.Table.from_pylist(list(rows), schema=self.schema)
        name = f"part-{self.next:06d}.parquet"
        tmp = self.path / f".{name}.tmp"
        pa.parquet.write_table(table, tmp, compression="zstd")
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
        os.replace(tmp, self.path / name)
        self.next += 1


def _csv_text(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)  # round-trips exactly
    return str(value)


def _csv_value(text: str, kind: type) -> Any:
    if text == "":
        return None
    if kind is int:
        return int(text)
    if kind is float:
        return float(text)
    if kind is bool:
        return text == "True"
    return text


class CsvWriter:
    """One CSV file with a header, appended a batch at a time (see the module's notes)."""

    def __init__(self, path: Path, meta: dict[str, Any]) -> None:
        self.path = path
        self.columns = [name for name, _ in ROW_COLUMNS]
        if path.exists() and path.stat().st_size > 0:
            self._drop_cut_line()
            with open(path, encoding="utf-8", newline="") as f:
                header = next(csv.reader(f), [])
            if header != self.columns[: len(header)] or not header:
                raise SweepError(f"{path}: not a results file of this version (its header differs)")
            # a file written before the last columns existed: its rows keep its columns (the
            # options of a resumed run are those of the file, so those columns are empty)
            self.columns = header
        else:
            with open(path, "w", encoding="utf-8", newline="") as f:
                csv.writer(f).writerow(self.columns)
        _append_run(path.with_name(path.name + ".meta.json"), meta)

    def _drop_cut_line(self) -> None:
        """Truncate the file after its last complete line (a crash may cut the last)."""
        with open(self.path, "rb+") as f:
            data = f.read()
            if data.endswith(b"\n"):
                return
            end = data.rfind(b"\n") + 1
            logger.warning("%s: dropping a cut last line (%d bytes)", self.path, len(data) - end)
            f.truncate(end)

    def done_keys(self) -> set[Key]:
        """``(path, sha256, options_key)`` of every row already in the file."""
        return {_key(r) for r in read_results(self.path, "csv")}

    def write(self, rows: Sequence[dict[str, Any]]) -> None:
        """Append rows and flush them to disk."""
        if not rows:
            return
        buf = io.StringIO()
        w = csv.writer(buf)
        for r in rows:
            w.writerow([_csv_text(r.get(c)) for c in self.columns])
        with open(self.path, "a", encoding="utf-8", newline="") as f:
            f.write(buf.getvalue())
            f.flush()
            os.fsync(f.fileno())


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif path.exists() or path.is_symlink():
        path.unlink()
    side = path.with_name(path.name + ".meta.json")
    if side.exists():
        side.unlink()


def _check_same_options(out: Path, options: SweepOptions) -> None:
    """Refuse to resume ``out`` with options none of its runs had (rows would mix).

    Raises
    ------
    SweepError
        Naming the options that differ from the last run's.
    """
    runs = read_metadata(out)
    if not runs or any(r.get("options_key") == options.key for r in runs):
        return
    stored = runs[-1].get("options", {})
    now = options.to_json()
    differ = [
        f"{k} {stored.get(k)!r} -> {now.get(k)!r}"
        for k in sorted(set(stored) | set(now))
        if stored.get(k) != now.get(k)
    ]
    raise SweepError(
        f"{out}: cannot resume: its rows were planned with other options "
        f"({'; '.join(differ) or 'a different options key'}); give the same options, "
        "another --out, or --force to replace it"
    )


def open_results(
    out: Path,
    options: SweepOptions,
    fmt: str | None = None,
    *,
    resume: bool = False,
    force: bool = False,
) -> ResultsWriter:
    """Open a results file for a run: new, resumed (``resume``) or replaced (``force``).

    Raises
    ------
    SweepError
        ``out`` exists and neither ``resume`` nor ``force`` is given; or it is not a
        results file of the format asked for.
    """
    kind = results_format(out, fmt)
    exists = out.exists() and (not out.is_dir() or any(out.iterdir()))
    if exists and resume:
        if kind == "parquet" and not out.is_dir():
            raise SweepError(f"{out}: cannot resume: not a Parquet results folder")
        if kind == "csv" and out.is_dir():
            raise SweepError(f"{out}: cannot resume: a folder, not a CSV results file")
        _check_same_options(out, options)
    elif exists:
        if not force:
            raise SweepError(f"{out} exists; resume it (--resume) or replace it (--force)")
        _remove(out)
    if not out.parent.is_dir():
        raise SweepError(f"{out}: no folder {str(out.parent)!r} to write into")
    meta = run_metadata(options)
    return ParquetWriter(out, meta) if kind == "parquet" else CsvWriter(out, meta)


def read_results(out: Path | str, fmt: str | None = None) -> list[dict[str, Any]]:
    """Every row of a results file, as dictionaries (in the order written).

    Examples
    --------
    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp()) / "r.csv"
    >>> w = open_results(out, SweepOptions())
    >>> w.write([{"path": "a.json", "sha256": "00", "options_key": "k", "sides": 4}])
    >>> [(r["path"], r["sides"], r["bayes_cost"]) for r in read_results(out)]
    [('a.json', 4, None)]
    """
    p = Path(out)
    kind = results_format(p, fmt)
    if kind == "csv":
        types = dict(ROW_COLUMNS)
        with open(p, encoding="utf-8", newline="") as f:
            reader = csv.DictReader(f)
            return [
                {k: _csv_value(v, types.get(k, str)) for k, v in r.items() if k is not None}
                for r in reader
                # a line cut by a crash has fewer fields (None values): it is not a row
                if None not in r and None not in r.values()
            ]
    pa = _pyarrow()
    rows: list[dict[str, Any]] = []
    for batch in sorted(p.glob("part-*.parquet")):
        rows += pa.parquet.read_table(batch).to_pylist()
    return rows


def read_metadata(out: Path | str) -> list[dict[str, Any]]:
    """The metadata of every run that wrote into a results file (oldest first)."""
    p = Path(out)
    side = p / "_sweep.json" if p.is_dir() else p.with_name(p.name + ".meta.json")
    if not side.exists():
        return []
    runs: list[dict[str, Any]] = json.loads(side.read_text(encoding="utf-8"))["runs"]
    return runs


def rows_by_key(rows: Iterable[dict[str, Any]]) -> dict[Key, dict[str, Any]]:
    """Rows keyed by ``(path, sha256, options_key)`` (the last row of a key wins)."""
    return {_key(r): r for r in rows}
