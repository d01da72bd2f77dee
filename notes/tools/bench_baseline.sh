#!/usr/bin/env bash
# The benches' regression guard. Criterion keeps a named baseline per bench
# under target/criterion/<group>/<bench>/<name>/; the committed one lives in
# notes/bench-baseline/ (same layout).
#   notes/tools/bench_baseline.sh compare   # current build against the committed baseline
#   notes/tools/bench_baseline.sh save      # run the benches, make them the committed baseline
# Extra arguments go to criterion (e.g. a filter: compare photon_pass).
# Compare on the same machine as the baseline, idle: the figures are wall times.
set -euo pipefail
cd "$(dirname "$0")/../.."
mode=${1:-compare}; shift || true
case "$mode" in
  compare)
    (cd notes/bench-baseline && find . -type d -name committed) | while read -r d; do
      mkdir -p "target/criterion/$d"
      cp -r "notes/bench-baseline/$d/." "target/criterion/$d/"
    done
    # Lenient: a bench added since the baseline was saved is measured, not an error.
    cargo bench --bench phases -- --baseline-lenient committed "$@"
    ;;
  save)
    cargo bench --bench phases -- --save-baseline committed "$@"
    rm -rf notes/bench-baseline
    (cd target/criterion && find . -type d -name committed) | while read -r d; do
      mkdir -p "notes/bench-baseline/$d"
      cp -r "target/criterion/$d/." "notes/bench-baseline/$d/"
    done
    ;;
  *) echo "usage: $0 compare|save [criterion args]" >&2; exit 2 ;;
esac
