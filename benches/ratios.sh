#!/usr/bin/env bash
# The ratios among issue 15's targets, at 2048² (BENCHMARKS.md, "`--maps roughness`
# against the full set, and a species without a film"):
#   crotalus-atrox, erythrolamprus-miliaris: `generate --maps roughness` over the full set;
#   xenopeltis-unicolor without its film (`--set optics.film_thickness_nm=0 --set
#   iridescence.spread_nm=0`) over the same preset with it.
#
# Usage: benches/ratios.sh RUNS [BINARY...]   (default binary: target/release/snakeskin)
#
# Every (binary, case) runs once per round, in an order shuffled each round (reproducibly):
# in a fixed order each run pays for the file write-back of the run before it. Wall times in
# ms; the medians over the rounds and their ratios are printed, one line per binary.
set -euo pipefail
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
runs=${1:?usage: benches/ratios.sh RUNS [BINARY...]}
shift
bins=("${@:-target/release/snakeskin}")
out=$scratch/out
times=$scratch/times
mkdir "$out" "$times"
# name|preset|extra arguments (split on spaces)
cases=(
    "crotalus-full|crotalus-atrox|"
    "crotalus-rough|crotalus-atrox|--maps roughness"
    "erythrolamprus-full|erythrolamprus-miliaris|"
    "erythrolamprus-rough|erythrolamprus-miliaris|--maps roughness"
    "xenopeltis-film|xenopeltis-unicolor|"
    "xenopeltis-nofilm|xenopeltis-unicolor|--set optics.film_thickness_nm=0 --set iridescence.spread_nm=0"
)
for round in $(seq "$runs"); do
    for b in "${!bins[@]}"; do
        for c in "${!cases[@]}"; do echo "$b $c"; done
    done | shuf --random-source=<(yes "$round") | while read -r b c; do
        IFS='|' read -r name preset extra <<<"${cases[$c]}"
        start=$(date +%s%N)
        # shellcheck disable=SC2086 # $extra is a list of arguments
        "${bins[$b]}" generate "$preset" -o "$out" --size 2048 $extra >/dev/null
        echo $((($(date +%s%N) - start) / 1000000)) >>"$times/$b.$name"
    done
done
ratio() { echo "$(median <"$times/$1.$2") $(median <"$times/$1.$3")" | awk '{printf "%d / %d = %.3f", $1, $2, $1 / $2}'; }
for b in "${!bins[@]}"; do
    echo "${bins[$b]}: crotalus-atrox roughness / full $(ratio "$b" crotalus-rough crotalus-full);" \
        "erythrolamprus-miliaris roughness / full $(ratio "$b" erythrolamprus-rough erythrolamprus-full);" \
        "xenopeltis-unicolor without / with film $(ratio "$b" xenopeltis-nofilm xenopeltis-film)"
done
