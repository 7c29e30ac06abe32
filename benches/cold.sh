#!/usr/bin/env bash
# A set generated the way a user runs one: after the machine has been idle, then twice more
# at once (BENCHMARKS.md, "Huge pages for large buffers"). `benches/species.sh` runs sets
# back to back, so it measures warm runs only; a change to how memory is obtained can win
# there and lose here (on a virtual machine that hands idle memory back to its host, the
# first run after an idle moment pays for memory the host must provide again).
#
# Usage: benches/cold.sh [BINARY] [PRESET] [SIZE] [ROUNDS] [IDLE_S]
#   defaults: target/release/snakeskin natrix-natrix 2048 3 25
# Output per round: wall, user and system seconds of the first run after IDLE_S seconds idle,
# then of the two runs that follow it.
set -euo pipefail
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
bin=${1:-target/release/snakeskin}
preset=${2:-natrix-natrix}
size=${3:-2048}
rounds=${4:-3}
idle=${5:-25}
run() { { /usr/bin/time -f '%e %U %S' "$bin" generate "$preset" -o "$scratch" --size "$size" >/dev/null; } 2>&1 | tail -1; }
for round in $(seq "$rounds"); do
    sleep "$idle"
    echo "round $round: cold $(run) | then $(run) | then $(run)"
done
