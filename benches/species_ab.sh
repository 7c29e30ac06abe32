#!/usr/bin/env bash
# Two binaries over every species at 2048² and 4096², interleaved: the comparison of
# BENCHMARKS.md's "before and after" tables (issue 15). `species.sh` runs one binary over
# every species and then the next, ten minutes apart, and this machine's speed drifts by
# 5–10 % over such a span; here each species' runs of the two binaries alternate.
#
# Usage: benches/species_ab.sh RUNS BEFORE AFTER > table.tsv
#
# Per species and size, RUNS rounds of (BEFORE, AFTER); wall seconds and the peak resident
# memory at 4096² by GNU time. Output: one tab-separated line per preset (name, then for
# each binary its 2K median s, 4K median s and largest 4K peak MiB), then the medians over
# the species (not the stress preset) and the geometric mean of the AFTER / BEFORE ratios.
set -euo pipefail
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
runs=${1:?usage: benches/species_ab.sh RUNS BEFORE AFTER}
bins=("${2:?before binary}" "${3:?after binary}")
printf 'preset\tbefore_2k_s\tbefore_4k_s\tbefore_4k_peak_mib\tafter_2k_s\tafter_4k_s\tafter_4k_peak_mib\n'
for preset in $(builtin_presets "${bins[0]}") tests/data/patterned.toml; do
    declare -A t2=() t4=() peak=()
    for _ in $(seq "$runs"); do
        for b in 0 1; do
            t2[$b]+="$( { /usr/bin/time -f '%e' "${bins[$b]}" generate "$preset" -o "$scratch" --size 2048 >/dev/null; } 2>&1 | tail -1) "
            line=$( { /usr/bin/time -f '%e %M' "${bins[$b]}" generate "$preset" -o "$scratch" --size 4096 >/dev/null; } 2>&1 | tail -1)
            t4[$b]+="${line% *} "
            kb=${line#* }
            (( kb > ${peak[$b]:-0} )) && peak[$b]=$kb
        done
    done
    row="$(basename "$preset" .toml)"
    for b in 0 1; do
        row+=$'\t'"$(tr ' ' '\n' <<<"${t2[$b]}" | grep . | median)"
        row+=$'\t'"$(tr ' ' '\n' <<<"${t4[$b]}" | grep . | median)"
        row+=$'\t'"$((peak[$b] / 1024))"
    done
    printf '%s\n' "$row"
    unset t2 t4 peak
done | tee "$scratch/table.tsv"
awk -F'\t' '$1 != "patterned" {
    n++; b2[n] = $2; b4[n] = $3; a2[n] = $5; a4[n] = $6; r2 += log($5 / $2); r4 += log($6 / $3)
    if ($4 > bp) bp = $4; if ($7 > ap) ap = $7
}
function med(a, n,   i, j, t) {
    for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
    return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
}
END {
    printf "# median species: before 2K %.3f s, 4K %.3f s; after 2K %.3f s, 4K %.3f s\n", med(b2, n), med(b4, n), med(a2, n), med(a4, n)
    printf "# after / before, geometric mean over %d species: 2K %.3f, 4K %.3f; largest 4K peak %d -> %d MiB\n", n, exp(r2 / n), exp(r4 / n), bp, ap
}' "$scratch/table.tsv"
