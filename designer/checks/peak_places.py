"""Where a pocket's 3-D peak stress sits, read again on the study table's rows (docs/model.md §7).

A slot's peak sits in one of two places: on the floor radius at one of its ends, where the
end mill's corner joins floor and end wall, or on the loaded outer face at the slot's rim (the
top of a thin side wall, or the rim of its end in a wide bar). The study records both peaks of
each feature (``study.Row.stress_floor``, ``stress_face`` and their ``_far`` twins); this
reads them on the table's rows made before it did. Each row's case is found again among
``study.cases()`` by its parameters and solved on the row's mesh alone (``fea.compare.one_mesh``:
the row's convergence figures stand); its station peaks must be the row's ``stress_ratio`` and
``stress_far`` again (the same mesh of the same solid), or the row is left as it is and said.

``python -m designer.checks.peak_places TABLE.csv [--family F ...] [--jobs 2]`` fills the
columns in, writing the table after each row.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from pathlib import Path

from designer.checks import study
from designer.checks.study_table import read_csv, write_rows

COLUMNS = ("stress_floor", "stress_face", "stress_floor_far", "stress_face_far")
# The solve again must give the row's station peaks to this share: the same mesh of the same solid.
SAME_SOLVE = 1e-3


def key(parameters: dict) -> tuple:
    """A row's or a case's parameters as the table writes them, for finding one by the other."""
    return tuple(sorted((k, f"{float(v):.6g}") for k, v in parameters.items()))


def pending(rows: list[dict], families) -> list[tuple[int, study.Case]]:
    """``(row index, case)`` of each row of ``families`` without the place columns whose case
    ``study.cases()`` still makes (found by the parameters the case's design gives)."""
    by_key, names = {}, {}
    for case, params in study.cases_with_parameters(families):
        names.setdefault(case.family, sorted(params))
        by_key.setdefault((case.family, key(params)), case)
    out = []
    for i, row in enumerate(rows):
        family = row["family"]
        if family not in names or not math.isnan(row.get(COLUMNS[0], math.nan)):
            continue
        case = by_key.get((family, key({k: row[k] for k in names[family] if k in row})))
        if case is not None:
            out.append((i, case))
    return out


def places(case: study.Case, mesh: str) -> tuple[tuple, tuple]:
    """A case's station peaks and ``COLUMNS``, each over its feature's nominal stress
    (``study.nominal_stresses``), from one mesh."""
    from designer.checks.fea.compare import one_mesh

    spec, result, raw = study.plain_case(case)
    nominal = study.nominal_stresses(result.evaluation.design.geometry, raw, spec)
    figures = one_mesh(result.record, mesh)
    peaks = tuple(p / n for p, n in zip(figures.station_peaks, nominal))
    return peaks, tuple(p / n for n, station in zip(nominal, figures.station_places) for p in station)


def _solve(job):
    index, case, mesh = job
    try:
        return index, places(case, mesh), None
    except Exception as exc:    # noqa: BLE001 - a case the 3-D check cannot do is said and left
        return index, None, f"{type(exc).__name__}: {exc}"


def _write(rows: list[dict], path: Path) -> None:
    """``rows`` over ``path`` whole or not at all."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        Path(tmp).write_bytes(path.read_bytes())   # write_rows takes the column order from the file
        write_rows(rows, Path(tmp))
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description="Read each pocket's floor-radius and outer-face 3-D peaks "
                                            "on the study table's rows that have none.")
    p.add_argument("table", type=Path, help="the study table (CSV), rewritten in place")
    p.add_argument("--family", action="append", help="only these families (default: rectangle-pocket)")
    p.add_argument("--jobs", type=int, default=2, help="cases solved at once (default 2)")
    p.add_argument("--limit", type=int, help="at most this many rows")
    args = p.parse_args(argv)
    families = args.family or ["rectangle-pocket"]
    rows = read_csv(args.table)
    todo = pending(rows, families)[:args.limit]
    print(f"{len(todo)} rows to solve", flush=True)
    jobs = [(i, case, rows[i]["mesh"]) for i, case in todo]
    from multiprocessing import get_context

    with get_context("spawn").Pool(args.jobs, maxtasksperchild=1) as pool:
        for index, got, failure in pool.imap_unordered(_solve, jobs):
            row = rows[index]
            if failure is not None:
                print(f"row {index}: left: {failure}", flush=True)
                continue
            peaks, figures = got
            same = [abs(a / row[k] - 1) for a, k in zip(peaks, ("stress_ratio", "stress_far"))]
            if max(same) > SAME_SOLVE:
                print(f"row {index}: left: the solve again gives peaks {peaks[0]:.4f}, {peaks[1]:.4f}, "
                      f"the row {row['stress_ratio']:.4f}, {row['stress_far']:.4f}", flush=True)
                continue
            row.update(zip(COLUMNS, figures))
            _write(rows, args.table)
            print(f"row {index}: floor {figures[0]:.3f} face {figures[1]:.3f} (peak {peaks[0]:.3f}); "
                  f"far floor {figures[2]:.3f} face {figures[3]:.3f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
