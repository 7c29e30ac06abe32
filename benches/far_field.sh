#!/usr/bin/env bash
# The preview's film colour seen from afar (BENCHMARKS.md, "Iridescence seen from afar: the
# thickness map's mips"): a frame at W x H against the same frame rendered K times as wide
# and tall and averaged over K x K blocks in linear light (a supersampled frame, the film
# colour averaged over each pixel's footprint), on the pixels the snake covers whole;
# CIEDE2000 and mean chroma, per pixel and over 4 x 4 blocks of pixels (where the mips'
# wider filter kernel no longer counts). Run with the species' thickness spread, shaded as
# the preview does (--film-footprint spread) and at the mean thickness alone (mean), and
# with one thickness (the control: the thickness map's mips then hold the thickness itself).
#   usage: benches/far_field.sh BIN [PRESET] [W H K]   (python3 with numpy and pillow)
set -euo pipefail
bin=$1; preset=${2:-xenopeltis-unicolor}; w=${3:-320}; h=${4:-200}; k=${5:-8}
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
spread=$("$bin" presets show "$preset" | sed -n 's/^spread_nm = \([0-9.]*\).*/\1/p')
for run in "$spread spread" "$spread mean" "0 spread"; do
  set -- $run
  # The supersampled frame shades the spread whichever way the far one does: at the mean
  # thickness alone, its pixels on a scale's edge would take the colour of a thickness no
  # scale has.
  for size in "${w}x${h} far $2" "$((w * k))x$((h * k)) near spread"; do
    set -- $run $size
    "$bin" preview "$preset" --no-ground --set iridescence.spread_nm="$1" --map-size 1024 \
      --film-footprint "$5" --size "$3" --out "$dir/$4.png" >/dev/null
  done
  printf 'spread_nm %s, --film-footprint %s:\n' "$1" "$2"
  python3 "$(dirname "$0")/far_field.py" "$dir/far.png" "$dir/near.png"
done
