"""Snapshot of every number the command line prints with ``--json`` (see ``generate.py``)."""
