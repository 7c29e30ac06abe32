# Helpers shared by the benchmark scripts (sourced, not run).

# The median of the numbers on standard input, one per line (the lower middle of an even count).
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }

# The names of BINARY's built-in presets, one per line.
builtin_presets() { "$1" presets list | tail -n +2 | awk '{print $1}'; }

# A scratch folder for the sets a script generates, removed when the script exits.
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
