#!/usr/bin/env bash
# Renders the independent references of the scene suite (scenes/suite/):
# each scene exported by `photonmap export --mitsuba` and rendered by
# Mitsuba 3's path tracer at 200 x 200 (tools/mitsuba_reference.py), into
# tests/data/suite/NAME.exr with NAME.json (spp, time, its own noise).
# Scene 1 is the default room, whose reference ships in tests/data/.
#
# usage: tools/suite_references.sh [SPP] [NAME ...]     (default 8192, all)
# (in tests/data/suite/ the sun window's reference has 32768, the Cornell
# box's 16384, the hall's 65536 and the small light's 40960: at 8192 their
# noise was larger than photonmap's error after a minute. The last two
# were extended: a second render with other seeds merged with the first's
# halves, tools/mitsuba_reference.py --add; the frosted glass's and the
# gold and glass's were rendered with VARIANT=cuda_ad_rgb on an NVIDIA
# H100: 1048576 and 2097152 spp, the first's window 4194304 (the gold and
# glass's whole image with the default placement, before its placement
# below was found; its window 16777216 with the placement below on the
# 2-core VM: CROP_SPP=8388608 PASSES=128, then as many again with --add); the
# envmap glass's window 4194304 with CROP_SPP=4194304 PASSES=64.
# The envmap glass's whole image (4788224 spp in 2338 passes of 2048) and
# the volume caustic's (146944 spp, 287 passes of 512; scene 13, exported
# with the default placement and rendered by volpath, as its XML says)
# with its cone's window (rows 124-172, columns 92-112: 1769472 spp, 54
# passes of 32768) were rendered with cuda_ad_rgb on an NVIDIA H200 by
# tools/mitsuba_passes.py (render OUT cuda_ad_rgb
# 11:11-envmap-glass.xml:2048:175:20000 13:13-volume-caustic.xml:512:200:30000
# 13c:13-volume-caustic.xml:32768:60:40000:124,172,92,112, then its exr
# mode): independent passes, their mean written with the per-pixel
# variance of the mean from the passes' spread, whose mean square root is
# the noise their JSON gives. At 65536 spp the envmap glass's noise estimate
# from two halves (0.0358) was ruled by a few heavy-tailed pixels (the sun
# through the glass); 2338 passes estimate it steadily (0.0206 at 280576
# spp falling as 1/sqrt(spp) to 0.0049).)
# Needs Mitsuba 3.9.1 in a Python (MITSUBA_PYTHON, default python3) and, for
# the llvm variant, DRJIT_LIBLLVM_PATH (see tools/mitsuba_reference.py).
# Hours of CPU: run it by hand, not in CI.
set -euo pipefail
cd "$(dirname "$0")/.."
spp=${1:-8192}
shift || true
py=${MITSUBA_PYTHON:-python3}
cargo build --release --bin photonmap -q
cargo run --release --example suite_meshes -q -- --large
out=tests/data/suite
work=$(mktemp -d)
mkdir -p "$out"
# name, caustic window (rows, columns of the 200 x 200 reference), and
# the export's placement where the default (origin at the eye, scale 1)
# leaves Mitsuba's ray offsets large against a small glass object or a
# sharp shadow (Mitsuba moves a ray's origin off the surface by about
# 9e-5 times 1 + its largest coordinate): the hall's ball (radius 0.15,
# 1.85 from the eye) refracts the window it shows 0.02 pixel off with the
# default, and within the reference's noise with the origin at its centre
# and lengths x100 (so the envmap glass's ball: at the default, the sun
# seen through its rim moved up to 18% per pixel); the sun window's patch border is 0.015 pixel off with
# the default, 0.006 with the origin at the patch (photonmap export --help;
# scenes/suite/suite.toml gives the same placement to the suite's
# equal-time Mitsuba renders).
scenes=(
  "02-cornell caustic=171:190,39:83 --origin -0.4,0.05,0.35 --scale 100"
  "03-knot caustic=100:141,94:135"
  "04-small-light caustic=176:192,130:154"
  "05-sun-window caustic=96:130,100:156 --origin 2.9,2.77,0 --scale 100"
  "06-water-glass caustic=115:156,95:175"
  "07-million caustic=100:141,94:135"
  "08-hall caustic=96:128,72:128 --origin 20,9.75,1.05 --scale 100"
  "09-frosted-glass caustic=120:142,86:128"
  "10-gold-glass caustic=121:134,134:152 --origin 0.7,0,0.5 --scale 100"
  "11-envmap-glass caustic=114:142,70:102 --origin 0,0.3,0.501 --scale 100"
)
for entry in "${scenes[@]}"; do
  read -r name window placement <<<"$entry"
  if [ $# -gt 0 ] && [[ ! " $* " == *" $name "* ]]; then continue; fi
  # shellcheck disable=SC2086 # the placement is words
  ./target/release/photonmap export --mitsuba "scenes/suite/$name.toml" "$work/$name.xml" ${placement:-}
  "$py" tools/mitsuba_reference.py "$work/$name.xml" "$out/$name.exr" --width 200 --height 200 \
    --spp "$spp" --passes "${PASSES:-16}" --window "$window" --keep-halves "$work" --variant "${VARIANT:-llvm_ad_rgb}"
  # The caustic window alone with many more samples (CROP_SPP, default
  # 262144), where suite.toml names it (caustic_reference): the window's
  # error is measurable below the whole reference's noise, at a fraction
  # of the whole image's cost (its pixels are ~4% of the image's).
  if grep -q "$name-caustic.exr" scenes/suite/suite.toml; then
    "$py" tools/mitsuba_reference.py "$work/$name.xml" "$out/$name-caustic.exr" --width 200 --height 200 \
      --spp "${CROP_SPP:-262144}" --passes "${PASSES:-16}" --crop "${window#caustic=}" --variant "${VARIANT:-llvm_ad_rgb}"
  fi
done
echo "halves kept in $work"
