#!/usr/bin/env python3
"""Mitsuba 3's path tracer on a scene for about SECONDS of wall time, loading
included, averaging 1-spp passes: the peer a photonmap render is compared
with at equal time (examples/suite.rs runs it).

usage: mitsuba_equal_time.py SCENE.xml SECONDS OUT.exr [--width W --height H]
                             [--variant llvm_ad_rgb]

No pass starts that the last pass's duration says would end past the
budget (at least one runs). Prints one JSON line: spp, seconds.
Setup as for tools/mitsuba_reference.py."""
import argparse, json, sys, time
import numpy as np

t0 = time.time()
ap = argparse.ArgumentParser()
ap.add_argument("scene"); ap.add_argument("seconds", type=float); ap.add_argument("out")
ap.add_argument("--width", type=int); ap.add_argument("--height", type=int)
ap.add_argument("--variant", default="llvm_ad_rgb"); ap.add_argument("--seed", type=int, default=77)
a = ap.parse_args()
import mitsuba as mi
from mitsuba_reference import write_exr
mi.set_variant(a.variant)
size = {k: v for k, v in (("width", a.width), ("height", a.height)) if v}
scene = mi.load_file(a.scene, spp=1, **size)
acc, n, last = None, 0, 0.0
while n == 0 or time.time() - t0 + last <= a.seconds:
    t1 = time.time()
    img = np.array(mi.render(scene, spp=1, seed=a.seed + n), dtype=np.float64)[..., :3]
    acc = img if acc is None else acc + img
    n += 1
    last = time.time() - t1
write_exr(a.out, acc / n)
print(json.dumps({"spp": n, "seconds": round(time.time() - t0, 2)}))
