#!/bin/sh
# Peak resident memory of `ridi track --online` (with and without a plot) and `ridi inspect` on
# long synthetic recordings, a RIDI data.csv and a raw folder, beside `ridi track` in batch,
# which reads the recording whole (docs/benchmarks.md, "Memory of long recordings").
# Usage: benchmarks/memory.sh [RIDI_BINARY] [ROWS...]
# Defaults: target/release/ridi (cargo build --release -p ridi-cli), 1000000 and 10000000 rows.
# Needs python3 and GNU time (/usr/bin/time); writes up to 3.1 GB into a temporary folder.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
ridi=${1:-$here/../target/release/ridi}
[ $# -gt 0 ] && shift
rows=${*:-1000000 10000000}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# A small model: two runs of the bundled sample, no grid search.
sample=$here/../datasets/sample
printf '%s,Swinging\n%s,Texting\n' "$sample/Jakob_Nexus5_NoDist_Swinging" \
    "$sample/Jakob_Nexus5_NoDist_Texting" > "$tmp/list.txt"
"$ridi" train --list "$tmp/list.txt" --out "$tmp/m.ridi" --grid none > /dev/null
for n in $rows; do
    python3 "$here/long_recording.py" "$n" "$tmp/long.csv"
    python3 "$here/long_recording.py" --raw "$n" "$tmp/raw"
    for source in long.csv raw; do
        /usr/bin/time -f "$n rows, $source: inspect peak %M KiB, %e s" \
            "$ridi" inspect "$tmp/$source" > /dev/null
        /usr/bin/time -f "$n rows, $source: track --online peak %M KiB, %e s" \
            "$ridi" track "$tmp/$source" --model "$tmp/m.ridi" --online --out "$tmp/t.csv" \
            > /dev/null
        /usr/bin/time -f "$n rows, $source: track --online --plot peak %M KiB, %e s" \
            "$ridi" track "$tmp/$source" --model "$tmp/m.ridi" --online --out "$tmp/t.csv" \
            --plot "$tmp/t.png" > /dev/null
        /usr/bin/time -f "$n rows, $source: track (batch, read whole) peak %M KiB, %e s" \
            "$ridi" track "$tmp/$source" --model "$tmp/m.ridi" --out "$tmp/t.csv" > /dev/null
    done
    rm -rf "$tmp/long.csv" "$tmp/raw" "$tmp/t.csv" "$tmp/t.png"
done
