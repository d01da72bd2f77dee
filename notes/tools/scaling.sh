#!/usr/bin/env bash
# Thread scaling of the default command: each phase's time at each thread
# count, medians over REPS rounds, and the speedup against the 1-thread run.
# Rounds go through the thread counts in turn (1, 2, 4, ..., then again) so
# that a slow period of a shared machine hits every count alike.
#
#   notes/tools/scaling.sh [BIN] [REPS] [THREADS...]
#   notes/tools/scaling.sh target/release/photonmap 3 1 2 4 8 12 16
#
# The project builds for the CPU that builds (.cargo/config.toml); for
# another machine build with RUSTFLAGS="-C target-cpu=x86-64-v3".
#
# Prints the raw runs as CSV (to $SCALING_CSV if set) and a markdown table.
set -euo pipefail

bin=${1:-target/release/photonmap}
reps=${2:-3}
shift 2 2>/dev/null || shift $#
threads=("$@")
if [ ${#threads[@]} -eq 0 ]; then
    threads=(1 2 4 8 12 16)
fi
photons=${SCALING_PHOTONS:-1e6}
csv=${SCALING_CSV:-$(mktemp)}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "round,threads,photon_pass_s,map_build_s,camera_pass_s,total_s,maps_s,irradiance_cache_s" >"$csv"
for round in $(seq 1 "$reps"); do
    for t in "${threads[@]}"; do
        "$bin" --photons "$photons" --threads "$t" "$work/out.exr" 2>"$work/log" >/dev/null
        awk -v r="$round" -v t="$t" '
            /^  photon pass/ { p = $3 }
            /^  map build/   { m = $3; k = $6; c2 = $10 }
            /^  camera pass/ { c = $3 }
            /^  total/       { s = $2 }
            END { printf "%s,%s,%s,%s,%s,%s,%s,%s\n", r, t, p, m, c, s, k, c2 }
        ' "$work/log" | tee -a "$csv"
    done
done

# Medians per thread count, then speedups against the 1-thread medians.
echo
echo "| threads | photon pass (s) | speedup | map build (s) | speedup | camera pass (s) | speedup | total (s) | speedup | maps (s) | speedup | irradiance cache (s) | speedup |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
awk -F, 'NR > 1 { n[$2]++; p[$2, n[$2]] = $3; m[$2, n[$2]] = $4; c[$2, n[$2]] = $5; s[$2, n[$2]] = $6; k[$2, n[$2]] = $7; e[$2, n[$2]] = $8 }
    function median(a, t, k,    i, j, v, x) {
        for (i = 1; i <= k; i++) v[i] = a[t, i]
        for (i = 2; i <= k; i++) { x = v[i]; for (j = i - 1; j >= 1 && v[j] > x; j--) v[j + 1] = v[j]; v[j + 1] = x }
        return k % 2 ? v[(k + 1) / 2] : (v[k / 2] + v[k / 2 + 1]) / 2
    }
    END {
        P1 = median(p, 1, n[1]); M1 = median(m, 1, n[1]); C1 = median(c, 1, n[1]); S1 = median(s, 1, n[1])
        K1 = median(k, 1, n[1]); E1 = median(e, 1, n[1])
        for (t = 1; t <= 1024; t++) if (t in n) {
            P = median(p, t, n[t]); M = median(m, t, n[t]); C = median(c, t, n[t]); S = median(s, t, n[t])
            K = median(k, t, n[t]); E = median(e, t, n[t])
            printf "| %d | %.3f | %.2fx | %.3f | %.2fx | %.3f | %.2fx | %.3f | %.2fx | %.3f | %.2fx | %.3f | %.2fx |\n", t, P, P1 / P, M, M1 / M, C, C1 / C, S, S1 / S, K, K1 / K, E, E1 / E
        }
    }' "$csv"
