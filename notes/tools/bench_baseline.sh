#!/usr/bin/env bash
# The benches' regression guard. Criterion keeps a named baseline per bench
# under target/criterion/<group>/<bench>/<name>/; the committed one lives in
# notes/bench-baseline/ (same layout).
#   notes/tools/bench_baseline.sh compare   # current build against the committed baseline
#   notes/tools/bench_baseline.sh save      # run the benches, make them the committed baseline
# Extra arguments go to criterion (e.g. a filter: compare photon_pass).
# Compare on the same machine as the baseline, idle: the figures are wall times.
# Both modes run the `floors` example first (and `save` again after the
# benches): a shared box's speed moves by tens of percent from hour to hour,
# and a bench that moved by as much as a random ray did is the machine, not
# the code. `save` keeps its readings in notes/bench-baseline/floors.txt;
# `compare` prints them beside the current ones.
set -euo pipefail
cd "$(dirname "$0")/../.."
mode=${1:-compare}; shift || true
floors() {
  cargo run --quiet --release --example floors | grep -E '^(closest hit|occlusion)'
}
# The first reading's ns per ray (closest hit, random rays in the room).
ray_ns() { sed -n '1s/.*: \([0-9.]*\) ns per ray.*/\1/p'; }
case "$mode" in
  compare)
    now=$(floors)
    echo "box now (floors):"; echo "$now" | sed 's/^/  /'
    if [[ -f notes/bench-baseline/floors.txt ]]; then
      echo "box when the baseline was saved (notes/bench-baseline/floors.txt):"
      sed 's/^/  /' notes/bench-baseline/floors.txt
      a=$(ray_ns < notes/bench-baseline/floors.txt); b=$(echo "$now" | ray_ns)
      if [[ -n "$a" && -n "$b" ]]; then
        awk -v a="$a" -v b="$b" 'BEGIN { printf "a random ray now takes %.2fx what it took then: read changes of that size as the machine'"'"'s\n", b / a }'
      fi
    fi
    (cd notes/bench-baseline && find . -type d -name committed) | while read -r d; do
      mkdir -p "target/criterion/$d"
      cp -r "notes/bench-baseline/$d/." "target/criterion/$d/"
    done
    # Lenient: a bench added since the baseline was saved is measured, not an error.
    cargo bench --bench phases -- --baseline-lenient committed "$@"
    ;;
  save)
    before=$(floors)
    cargo bench --bench phases -- --save-baseline committed "$@"
    after=$(floors)
    rm -rf notes/bench-baseline
    (cd target/criterion && find . -type d -name committed) | while read -r d; do
      mkdir -p "notes/bench-baseline/$d"
      cp -r "target/criterion/$d/." "notes/bench-baseline/$d/"
    done
    { echo "$before"; echo "after the benches:"; echo "$after"; } > notes/bench-baseline/floors.txt
    echo "floors before and after (notes/bench-baseline/floors.txt): a save is worth committing only if they agree with those of an idle machine"
    cat notes/bench-baseline/floors.txt
    ;;
  *) echo "usage: $0 compare|save [criterion args]" >&2; exit 2 ;;
esac
