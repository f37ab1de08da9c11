"""Record the design and predictions fpdesign gives for a folder of specs, or compare two records.

    python benchmarks/compare_records.py record SPEC_DIR OUT.json   # runs the installed fpdesign
    python benchmarks/compare_records.py compare OLD.json NEW.json [--rtol 1e-9]

``record`` runs ``fpdesign optimize`` (or ``evaluate`` for a spec with a ``design:`` block) with
``--no-cad --no-plots`` on every ``*.yaml`` of SPEC_DIR through the command line, so two versions
of the package with different internals can be compared. ``compare`` checks the status, the
``design`` and the ``predicted`` blocks of design.json number by number and prints every
difference above the relative tolerance. A refactoring must leave them equal.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path


def record(spec_dir: Path, out: Path) -> int:
    results = {}
    for path in sorted(spec_dir.glob("*.yaml")):
        command = "evaluate" if "\ndesign:" in path.read_text(encoding="utf-8") else "optimize"
        with tempfile.TemporaryDirectory() as tmp:
            run = subprocess.run(["fpdesign", command, str(path), "-o", tmp, "--no-cad", "--no-plots"]
                                 + (["--quiet"] if command == "optimize" else []),
                                 capture_output=True, text=True)
            design_json = Path(tmp) / "design.json"
            if not design_json.exists():
                results[path.stem] = {"exit": run.returncode, "stderr": run.stderr.strip()[-300:]}
            else:
                rec = json.loads(design_json.read_text())
                results[path.stem] = {"exit": run.returncode, "status": rec["status"],
                                      "design": rec["design"], "predicted": rec["predicted"]}
        print(f"{path.stem}: exit {run.returncode}", flush=True)
    out.write_text(json.dumps(results, indent=1, sort_keys=True))
    return 0


def _differences(a, b, where: str, rtol: float):
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            if key not in a or key not in b:
                yield f"{where}.{key}: only in {'new' if key not in a else 'old'}"
            else:
                yield from _differences(a[key], b[key], f"{where}.{key}", rtol)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            yield f"{where}: {len(a)} items against {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            yield from _differences(x, y, f"{where}[{i}]", rtol)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        if not (a == b or math.isclose(a, b, rel_tol=rtol, abs_tol=0.0)):
            yield f"{where}: {a!r} against {b!r} (relative {abs(a - b) / max(abs(a), abs(b)):.2e})"
    elif a != b:
        yield f"{where}: {a!r} against {b!r}"


def compare(old: Path, new: Path, rtol: float) -> int:
    a, b = json.loads(old.read_text()), json.loads(new.read_text())
    diffs = list(_differences(a, b, "", rtol))
    for line in diffs:
        print(line)
    print(f"{len(a)} specs compared, {len(diffs)} differences above relative {rtol:g}")
    return 1 if diffs else 0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("record")
    r.add_argument("spec_dir", type=Path)
    r.add_argument("out", type=Path)
    c = sub.add_parser("compare")
    c.add_argument("old", type=Path)
    c.add_argument("new", type=Path)
    c.add_argument("--rtol", type=float, default=1e-9)
    args = p.parse_args(argv)
    if args.command == "record":
        return record(args.spec_dir, args.out)
    return compare(args.old, args.new, args.rtol)


if __name__ == "__main__":
    sys.exit(main())
