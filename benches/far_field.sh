#!/usr/bin/env bash
# The preview's film colour seen from afar (BENCHMARKS.md, "Iridescence seen from afar: the
# thickness map's mips"): a frame at W x H against the same frame rendered K times as wide
# and tall and averaged over K x K blocks in linear light (a supersampled frame, the film
# colour averaged over each pixel's footprint), on the pixels the snake covers whole;
# CIEDE2000 and mean chroma. Run with the species' thickness spread and with one thickness
# (the control: the thickness map's mips then hold the thickness itself).
#   usage: benches/far_field.sh BIN [PRESET] [W H K]   (python3 with numpy and pillow)
set -euo pipefail
bin=$1; preset=${2:-xenopeltis-unicolor}; w=${3:-320}; h=${4:-200}; k=${5:-8}
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
spread=$("$bin" presets show "$preset" | sed -n 's/^spread_nm = \([0-9.]*\).*/\1/p')
for s in "$spread" 0; do
  "$bin" preview "$preset" --no-ground --set iridescence.spread_nm="$s" --map-size 1024 \
    --size "${w}x${h}" --out "$dir/far.png" >/dev/null
  "$bin" preview "$preset" --no-ground --set iridescence.spread_nm="$s" --map-size 1024 \
    --size "$((w * k))x$((h * k))" --out "$dir/near.png" >/dev/null
  printf 'spread_nm %s: ' "$s"
  python3 "$(dirname "$0")/far_field.py" "$dir/far.png" "$dir/near.png"
done
