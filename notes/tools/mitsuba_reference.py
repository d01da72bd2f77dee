#!/usr/bin/env python3
"""Independent reference for the default scene from another eye position,
rendered with Mitsuba 3's unbiased path tracer (the peer of shared/refs/).

usage: mitsuba_reference.py SCENE.xml RES SPP OUT.exr [PASSES]

SCENE.xml is shared/peers/mitsuba/tncg15_default.xml with the sensor moved;
for eye 2 (e2 = (-1,0,0), 90 degrees) it is made by
  sed -e 's/origin="-2, 0, 0"/origin="-1, 0, 0"/' \
      -e 's/<float name="fov" value="53.130102354"\\/>/<float name="fov" value="90"\\/>/'
The passes are averaged in float64 and written as float32 EXR.
Setup: python3 -m venv V && V/bin/pip install mitsuba==3.9.1 numpy openexr, and
DRJIT_LIBLLVM_PATH pointing at libLLVM >= 16 (see shared/peers/mitsuba/equal_time.py).
Not a dependency of the project and not run in CI: its output is committed in
tests/data/."""
import sys, time
import numpy as np
import mitsuba as mi

mi.set_variant("llvm_ad_rgb")
xml, res, spp, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
passes = int(sys.argv[5]) if len(sys.argv) > 5 else 16
scene = mi.load_file(xml, res=res, spp=spp // passes)
acc = np.zeros((res, res, 3))
t0 = time.time()
for p in range(passes):
    acc += np.array(mi.render(scene, spp=spp // passes, seed=1000 + p), dtype=np.float64)[..., :3]
    print(f"pass {p + 1}/{passes} {time.time() - t0:.0f}s", flush=True)
img = np.ascontiguousarray(acc / passes, dtype=np.float32)
import OpenEXR
header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
with OpenEXR.File(header, {"R": img[..., 0].copy(), "G": img[..., 1].copy(), "B": img[..., 2].copy()}) as f:
    f.write(out)
print(f"{spp} spp at {res}x{res} in {time.time() - t0:.0f}s -> {out}; mean {img.mean():.5f}")
