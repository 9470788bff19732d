"""The gallery: the views users saved on this server, kept in SQLite, bounded in rows.

One row a saved view: its name, the page's address fragment (the part as the user gave it
and every option, so the entry reproduces the view), the outline for a thumbnail and the
plan's numbers. Saving the same view again only refreshes its time; when there are more than
``max_rows`` rows the oldest go. Nothing is recorded unless a user saves it.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import sqlite3
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

__all__ = ["DEFAULT_MAX_ROWS", "Gallery", "default_data_dir"]

DEFAULT_MAX_ROWS = 500
"""Rows the gallery keeps by default."""

_SCHEMA = """
CREATE TABLE IF NOT EXISTS saved (
    key TEXT PRIMARY KEY,
    name TEXT NOT NULL,
    view TEXT NOT NULL,
    outline TEXT NOT NULL,
    summary TEXT NOT NULL,
    saved REAL NOT NULL
)
"""


def default_data_dir() -> Path:
    """The user data folder: platformdirs' when installed, else ``$XDG_DATA_HOME/bayesgrasp``.

    Examples
    --------
    >>> default_data_dir().name
    'bayesgrasp'
    """
    try:
        from platformdirs import user_data_dir
    except ImportError:
        base = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
        return Path(base) / "bayesgrasp"
    return Path(user_data_dir("bayesgrasp", appauthor=False))


class Gallery:
    """The gallery database ``gallery.sqlite3`` in a data folder.

    Parameters
    ----------
    data_dir : str or Path
        Folder of the database (created).
    max_rows : int
        Most rows kept (the oldest go first).

    Examples
    --------
    >>> import tempfile
    >>> g = Gallery(tempfile.mkdtemp(), max_rows=1)
    >>> _ = g.save("a", "part=house", [[0, 0], [1, 0], [0, 1]], {})
    >>> _ = g.save("b", "part=key", [[0, 0], [2, 0], [0, 1]], {})
    >>> [row["name"] for row in g.saved_page(1, 10)["rows"]], len(g)
    (['b'], 1)
    """

    def __init__(self, data_dir: str | Path, max_rows: int = DEFAULT_MAX_ROWS) -> None:
        if max_rows < 1:
            raise ValueError(f"`max_rows` must be at least 1; got {max_rows}")
        self.path = Path(data_dir) / "gallery.sqlite3"
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.max_rows = max_rows
        self._lock = threading.Lock()
        with self._connect() as db:
            db.execute("PRAGMA journal_mode=WAL")  # readers do not wait for the writer
            db.executescript(_SCHEMA)

    @contextlib.contextmanager
    def _connect(self) -> Iterator[sqlite3.Connection]:
        """A connection in a transaction (committed on success), closed afterwards."""
        db = sqlite3.connect(self.path, timeout=10)
        db.execute("PRAGMA synchronous=NORMAL")  # a lost last row on power loss is fine
        try:
            with db:
                yield db
        finally:
            db.close()

    def save(
        self, name: str, view: str, outline: list[list[float]], summary: dict[str, Any]
    ) -> str:
        """Keep a view the user saved: its address fragment, outline and plan numbers.

        ``view`` is the page's address fragment (the part and every option), so the entry
        reproduces the view; saving the same view again only refreshes its time. Returns the
        entry's id.

        Examples
        --------
        >>> import tempfile
        >>> g = Gallery(tempfile.mkdtemp())
        >>> i = g.save("a", "part=house", [[0, 0], [1, 0], [0, 1]], {"expected_cost": 2.0})
        >>> page = g.saved_page(1, 10)
        >>> page["total"], page["rows"][0]["id"] == i, page["rows"][0]["view"]
        (1, True, 'part=house')
        """
        key = hashlib.sha256(view.encode()).hexdigest()
        row = (
            key,
            name[:80],
            view,
            json.dumps(outline, separators=(",", ":")),
            json.dumps(summary, sort_keys=True, separators=(",", ":")),
            time.time(),
        )
        with self._lock, self._connect() as db:
            db.execute("INSERT OR REPLACE INTO saved VALUES (?, ?, ?, ?, ?, ?)", row)
            db.execute(
                "DELETE FROM saved WHERE key NOT IN "
                "(SELECT key FROM saved ORDER BY saved DESC, rowid DESC LIMIT ?)",
                (self.max_rows,),
            )
        return key[:16]

    def saved_page(self, page: int, per_page: int) -> dict[str, Any]:
        """One page (from 1) of the saved views, newest first, and how many there are."""
        page, per_page = max(1, page), max(1, per_page)
        with self._lock, self._connect() as db:
            (total,) = db.execute("SELECT COUNT(*) FROM saved").fetchone()
            found = db.execute(
                "SELECT key, name, view, outline, summary, saved FROM saved "
                "ORDER BY saved DESC, rowid DESC LIMIT ? OFFSET ?",
                (per_page, (page - 1) * per_page),
            ).fetchall()
        rows = [
            {
                "id": key[:16],
                "name": name,
                "view": view,
                "outline": json.loads(outline),
                "summary": json.loads(summary),
                "saved": t,
            }
            for key, name, view, outline, summary, t in found
        ]
        return {"page": page, "per_page": per_page, "total": int(total), "rows": rows}

    def __len__(self) -> int:
        """The number of saved views."""
        with self._lock, self._connect() as db:
            (n,) = db.execute("SELECT COUNT(*) FROM saved").fetchone()
        return int(n)
