"""The 3-D study's table (``materials/corrections_study.csv``) as files: its rows written as the
study runs them (``write_csv``), read back as dictionaries of floats (``read_csv``), and written back
after a change (``write_rows``). Lines end in a bare newline, as the shipped table's do."""

from __future__ import annotations

import csv
from dataclasses import fields
from pathlib import Path


def write_csv(rows: list, path: Path) -> None:
    """``study.Row``s as the table, a column per parameter any of them has."""
    keys = sorted({k for r in rows for k in r.parameters})
    names = [f.name for f in fields(rows[0]) if f.name != "parameters"] if rows else []
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(names[:2] + keys + names[2:])
        for r in rows:
            values = [getattr(r, n) for n in names]
            w.writerow(values[:2] + [_cell(r.parameters[k]) if k in r.parameters else "" for k in keys]
                       + [_cell(v) for v in values[2:]])


def write_rows(rows: list[dict], path: Path) -> None:
    """Table rows as ``read_csv`` gives them, written back in the table's column order (a new
    column, such as ``base_ratio``, last)."""
    with open(path, newline="", encoding="utf-8") as fh:
        header = next(csv.reader(fh))
    header += [k for r in rows for k in r if k not in header]
    header = list(dict.fromkeys(header))
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(header)
        for r in rows:
            w.writerow([_cell(r[k]) if k in r else "" for k in header])


def _cell(value) -> str:
    """A table cell: a float to 6 significant figures, text as it is."""
    return f"{value:.6g}" if isinstance(value, float) else value


def read_csv(path: Path) -> list[dict]:
    """The study table as dictionaries of floats (the family as text)."""
    with open(path, newline="", encoding="utf-8") as fh:
        return [{k: (v if k in ("family", "mesh") else float(v)) for k, v in row.items() if v != ""}
                for row in csv.DictReader(fh)]
