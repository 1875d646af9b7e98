#!/usr/bin/env bash
# The relation benchmark's twelve replays natively, for measuring a setting:
# the four raw Freiburg bags (../shared/data/bags/freiburg, or
# $SLAMLAB_DATA/bags/freiburg) whole and each half on its own, two at a
# time, through `cargo run --release --example bag_replay`, with
# SLAMLAB_LOG_SLAM="key=value,..." (tests/real_support/mod.rs lists the
# keys). Prints one line per replay: its relation figures.
#
#   tests/bench/relations_native.sh ["key=value,..."]
set -euo pipefail
cd "$(dirname "$0")/../.."
data="${SLAMLAB_DATA:-$(pwd)/../shared/data}/bags/freiburg"
[ -f "$data/aces.bag" ] || { echo "error: no raw Freiburg bags at $data" >&2; exit 1; }
cargo build --release -q -p slamlab --example bag_replay
bin=target/release/examples/bag_replay
out=$(mktemp -d)
for log in aces intel mit-csail fr079; do
  for half in whole first second; do
    # (no trailing blank: xargs -L would join the next line)
    if [ "$half" = whole ]; then echo "$log $half"; else echo "$log $half --half $half"; fi
  done
done | xargs -P 2 -L 1 sh -c 'SLAMLAB_LOG_SLAM="$0" '"$bin"' "'"$data"'/$1.bag" --relations "'"$data"'/$1.relations" $3 $4 > "'"$out"'/$1-$2.txt" 2>&1' "${1:-}"
for log in aces intel mit-csail fr079; do
  for half in whole first second; do
    printf '%-10s %-7s %s\n' "$log" "$half" "$(grep '^relations:' "$out/$log-$half.txt" | sed 's/^relations: //')"
  done
done
rm -rf "$out"
