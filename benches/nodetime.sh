#!/usr/bin/env bash
# Node time by operation (BENCHMARKS.md, "node time by operation"): every built-in species
# generated with `--stats`, each node's wall time summed by the kind of operation, divided
# by the number of species. Wall times with all cores: nodes that run side by side overlap.
#
# Usage: benches/nodetime.sh [BINARY] [SIZE]   (defaults: target/release/snakeskin, 2048)
# Output: a Markdown table, operation | nodes | mean ms per species, slowest first.
set -euo pipefail
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
bin=${1:-target/release/snakeskin}
size=${2:-2048}
presets=$(builtin_presets "$bin")
echo "| operation | nodes | mean ms per species |"
echo "|---|---:|---:|"
for preset in $presets; do
    "$bin" generate "$preset" -o "$scratch" --size "$size" --stats 2>&1
done | awk -v species="$(echo "$presets" | wc -l)" '
    # The stats table: a header, then "name operation... evals ms MiB" per node.
    /^node +operation/ { table = 1; next }
    table && NF >= 5 && $(NF - 2) ~ /^[0-9]+$/ && $(NF - 1) ~ /^[0-9.]+$/ {
        op = $2
        for (i = 3; i <= NF - 3; i++) op = op " " $i
        if (op ~ /^scales /) kind = "scale lattice"
        else if (op ~ /^fused/) kind = "fused per-pixel chains"
        else if (op ~ /^noise/) kind = "noise (Perlin and cellular)"
        else if (op ~ /^blur/) kind = "blur"
        else if (op ~ /^height to normal/) kind = "height to normal"
        else if (op ~ /^colour per scale/) kind = "colour per scale"
        else if (op ~ /^snap/) kind = "snap to scales"
        else if (op ~ /^sobel/) kind = "Sobel"
        else if (op ~ /^bands/) kind = "bands"
        else if (op ~ /^channel/) kind = "channel copies (unfused)"
        else if (op ~ /^constant/) kind = "constants"
        else kind = "other"
        ms[kind] += $(NF - 1)
        nodes[kind]++
        next
    }
    { table = 0 }
    END {
        for (k in ms) printf "%.1f\t| %s | %d | %.1f |\n", ms[k] / species, k, nodes[k], ms[k] / species
    }' | sort -t$'\t' -k1,1 -g -r | cut -f2-
