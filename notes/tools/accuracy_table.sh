#!/usr/bin/env bash
# Renders the default scene at several photon counts and scores each render
# against the reference; appends CSV rows to notes/accuracy.csv.
# usage: notes/tools/accuracy_table.sh [EYE] [EXTRA PHOTONMAP OPTIONS...]
# Run on an otherwise idle machine: wall times are part of the result.
set -euo pipefail
cd "$(dirname "$0")/../.."
eye=${1:-1}; shift || true
ref=tests/data/default_e${eye}_200.exr
cargo build --release --quiet
csv=notes/accuracy.csv
[ -f "$csv" ] || echo "eye,photons,caustic_photons,spp,gather_rays,extra,wall_s,rmse,relmse,caustic_rmse,mean_x,mean_r,caustic_mean_x,caustic_mean_r,nan_count" > "$csv"
for photons in ${PHOTONS:-1e5 1e6 1e7}; do
  out=$(mktemp --suffix .exr)
  start=$(date +%s.%N)
  json=$(./target/release/photonmap --eye "$eye" --photons "$photons" -q "$@" "$out" --reference "$ref")
  end=$(date +%s.%N)
  rm -f "$out"
  wall=$(echo "$end - $start" | bc)
  row=$(python3 -c "import json,sys; m=json.loads(sys.argv[1]); print(','.join(str(m[k]) for k in ['rmse','relmse','caustic_rmse','mean_x','mean_r','caustic_mean_x','caustic_mean_r','nan_count']))" "$json")
  echo "$eye,$photons,$photons,4,4,\"$*\",$wall,$row" | tee -a "$csv"
done
