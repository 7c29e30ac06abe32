#!/usr/bin/env bash
# Per-species wall time and peak resident memory of `snakeskin generate`, the table of
# BENCHMARKS.md "Every species at 2K and 4K" (issue 15).
#
# Usage: benches/species.sh [BINARY] [RUNS] > table.tsv
#   BINARY  the snakeskin binary (default target/release/snakeskin)
#   RUNS    runs per species and size; the median is reported (default 3)
#
# Each species is generated at 2048² and 4096² (five maps, PNG files written to a scratch
# folder, both cores), timed by GNU time: wall seconds and "maximum resident set size".
# Output: one tab-separated line per preset: name, 2K median s, 4K median s, 4K peak MiB
# (the largest of the runs).
set -euo pipefail
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
bin=${1:-target/release/snakeskin}
runs=${2:-3}
printf 'preset\t2k_s\t4k_s\t4k_peak_mib\n'
for preset in $(builtin_presets "$bin") tests/data/patterned.toml; do
    t2=() t4=() peak=0
    for _ in $(seq "$runs"); do
        t2+=("$( { /usr/bin/time -f '%e' "$bin" generate "$preset" -o "$scratch" --size 2048 >/dev/null; } 2>&1 | tail -1)")
        line=$( { /usr/bin/time -f '%e %M' "$bin" generate "$preset" -o "$scratch" --size 4096 >/dev/null; } 2>&1 | tail -1)
        t4+=("${line% *}")
        kb=${line#* }
        (( kb > peak )) && peak=$kb
    done
    printf '%s\t%s\t%s\t%d\n' "$(basename "$preset" .toml)" \
        "$(printf '%s\n' "${t2[@]}" | median)" "$(printf '%s\n' "${t4[@]}" | median)" $((peak / 1024))
done
