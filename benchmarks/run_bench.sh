#!/bin/sh
# The method comparison quoted in the README: every search method on the optimiser examples and
# 50 generated specs (seed 0), then the summary and chart copied to benchmarks/bench_methods.*.
# Usage: sh benchmarks/run_bench.sh [extra fpdesign bench options]
set -eu
here=$(cd "$(dirname "$0")" && pwd)
out=$(mktemp -d "${TMPDIR:-/tmp}/fpdesign-bench.XXXXXX")
trap 'rm -rf "$out"' EXIT
cd "$here/.."
python -m designer.cli bench --specs "$here/../examples" --count 50 --seed 0 -o "$out/bench" "$@"
sed -e 's/(bench\.png)/(bench_methods.png)/' -e '/^Files: `runs.csv`/d' "$out/bench/bench.md" > "$here/bench_methods.md.tmp"
cp "$out/bench/bench.png" "$here/bench_methods.png.tmp"
mv "$here/bench_methods.md.tmp" "$here/bench_methods.md"
mv "$here/bench_methods.png.tmp" "$here/bench_methods.png"
echo "wrote $here/bench_methods.md and $here/bench_methods.png"
