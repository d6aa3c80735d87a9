#!/usr/bin/env bash
# The paper's Table 1 on a lent GPU machine (docs/benchmarks/render.md, "Table 1 on a
# GPU"): the histogram pass's share of a strata frame at 1920 x 1080 with 16 x 16 blocks,
# and every method's frame time, from the `table1` criterion bench.
#
# The bench is built here, where Rust is installed, and its executable carried to the
# device machine (which has a GPU driver, not necessarily a Rust toolchain):
#
#   cargo bench -p strata-benches --bench table1 --no-run   # prints the executable's path
#   (the device tool: carry that path as the repository gives it, target/release/deps/
#   table1-HASH, and run `benchmarks/device/table1.sh target/release/deps/table1-HASH`)
#
# Writes, under $OUT (the device tool's folder; target/table1 elsewhere): machine.txt
# (the GPU and driver), table1.txt (criterion's output and the per-pass lines); prints
# the `table1:` line at the end. On a CPU device set STRATA_TABLE1_SIZE=160x90 to try it.
set -euo pipefail
bench=${1:?usage: benchmarks/device/table1.sh BENCH_EXECUTABLE (from cargo bench -p strata-benches --bench table1 --no-run)}
[ -f "$bench" ] && [ -x "$bench" ] || { echo "error: $bench: not an executable file" >&2; exit 1; }
out=${OUT:-target/table1}
mkdir -p "$out"
{
  date -u
  nvidia-smi -L 2>/dev/null || echo "nvidia-smi: not found"
  nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv 2>/dev/null || true
} > "$out/machine.txt"
# A new folder of a random name for the Vulkan loader's runtime directory, never a fixed
# name in /tmp (SECURITY.md, "The display socket").
runtime=$(mktemp -d)
trap 'rm -rf "$runtime"' EXIT
XDG_RUNTIME_DIR=$runtime "$bench" --bench 2>&1 | tee "$out/table1.txt"
grep "^table1:" "$out/table1.txt" \
  || { echo "error: no table1 line; see $out/table1.txt (no GPU adapter, or no timestamp queries?)" >&2; exit 1; }
