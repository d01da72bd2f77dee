#!/usr/bin/env python3
"""An independent reference for a scene: Mitsuba 3's unbiased path tracer on
the scene as `photonmap export --mitsuba` writes it.

usage: mitsuba_reference.py SCENE.xml OUT.exr --width W --height H --spp N
                            [--passes P] [--window NAME=R0:R1,C0:C1 ...]
                            [--crop R0:R1,C0:C1]
                            [--variant llvm_ad_rgb] [--seed S] [--keep-halves DIR]
                            [--add STEM --add-spp M]

Renders P passes of N/P samples per pixel (independent seeds), averages them
in float64 and writes OUT.exr (float32 RGB). Its own noise is estimated by
splitting the passes into two halves A and B: the RMSE of the full average
is RMSE(A - B) / 2 (each half has twice the variance of the whole). Writes
OUT.json beside it: spp, passes, seconds, the Mitsuba version, and that noise
for the whole image and for each window (rows and columns of OUT.exr,
half-open). With --crop, only that rectangle of the W x H image is
rendered (many samples for a window at a fraction of the whole image's
cost): OUT.exr holds the rectangle, and OUT.json says where it lies
("crop": rows and columns). With --add, the halves of an earlier render
of the same scene (STEM.half-a.exr, STEM.half-b.exr, written by
--keep-halves, M samples per pixel in all) are merged in, weighted by
their samples: give this run seeds the earlier one did not use (it used
S to S + P - 1). Not a dependency of the project and not run in CI: its outputs
are committed under tests/data/.

Setup: python3 -m venv V && V/bin/pip install mitsuba==3.9.1 numpy openexr.
The llvm variant needs libLLVM >= 16: on Debian 12,
  apt-get download libllvm19 && dpkg-deb -x libllvm19_*.deb llvm19
  export DRJIT_LIBLLVM_PATH=$PWD/llvm19/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
(or --variant scalar_rgb, slower)."""
import argparse, json, sys, time
import numpy as np


def write_exr(path, img):
    import OpenEXR
    img = np.ascontiguousarray(img, dtype=np.float32)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    chans = {"R": img[..., 0].copy(), "G": img[..., 1].copy(), "B": img[..., 2].copy()}
    with OpenEXR.File(header, chans) as f:
        f.write(path)


def read_exr(path):
    import OpenEXR
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            return np.array(ch["RGB"].pixels, dtype=np.float64)
        return np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)


def parse_window(text):
    name, _, spec = text.rpartition("=")
    rows, cols = spec.split(",")
    r0, r1 = (int(v) for v in rows.split(":"))
    c0, c1 = (int(v) for v in cols.split(":"))
    return name or "window", (r0, r1, c0, c1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene"); ap.add_argument("out")
    ap.add_argument("--width", type=int, required=True); ap.add_argument("--height", type=int, required=True)
    ap.add_argument("--spp", type=int, required=True); ap.add_argument("--passes", type=int, default=16)
    ap.add_argument("--window", action="append", default=[])
    ap.add_argument("--crop", help="render only rows R0:R1, columns C0:C1 of the image")
    ap.add_argument("--variant", default="llvm_ad_rgb"); ap.add_argument("--seed", type=int, default=1000)
    ap.add_argument("--keep-halves", metavar="DIR", help="also write the two halves' averages there")
    ap.add_argument("--add", metavar="STEM", help="merge the halves of an earlier render (STEM.half-a.exr, .half-b.exr)")
    ap.add_argument("--add-spp", type=int, help="samples per pixel of the render --add names")
    a = ap.parse_args()
    if (a.add is None) != (a.add_spp is None):
        sys.exit("--add and --add-spp go together")
    import mitsuba as mi
    mi.set_variant(a.variant)
    passes = max(2, a.passes - a.passes % 2)
    per = max(1, a.spp // passes)
    if a.crop:
        import os
        _, (r0, r1, c0, c1) = parse_window(a.crop)
        if not (0 <= r0 < r1 <= a.height and 0 <= c0 < c1 <= a.width):
            sys.exit(f"--crop {a.crop}: not inside the {a.width} x {a.height} image")
        with open(a.scene) as f:
            xml = f.read()
        film = '<film type="hdrfilm">'
        if xml.count(film) != 1:
            sys.exit(f"{a.scene}: no single '{film}' to crop")
        xml = xml.replace(film, film + "".join(
            f'<integer name="{k}" value="{v}"/>'
            for k, v in [("crop_offset_x", c0), ("crop_offset_y", r0), ("crop_width", c1 - c0), ("crop_height", r1 - r0)]))
        mi.file_resolver().prepend(os.path.dirname(os.path.abspath(a.scene)))
        scene = mi.load_string(xml, spp=per, width=a.width, height=a.height)
        shape = (r1 - r0, c1 - c0, 3)
    else:
        scene = mi.load_file(a.scene, spp=per, width=a.width, height=a.height)
        shape = (a.height, a.width, 3)
    halves = [np.zeros(shape), np.zeros(shape)]
    t0 = time.time()
    for p in range(passes):
        img = np.array(mi.render(scene, spp=per, seed=a.seed + p), dtype=np.float64)[..., :3]
        halves[p % 2] += img
        print(f"pass {p + 1}/{passes}  {time.time() - t0:.0f} s", file=sys.stderr, flush=True)
    seconds = time.time() - t0
    a_half, b_half = (h / (passes // 2) for h in halves)
    spp = per * passes
    if a.add:
        earlier = [read_exr(f"{a.add}.half-{h}.exr") for h in "ab"]
        if any(e.shape != shape for e in earlier):
            sys.exit(f"{a.add}: halves of {earlier[0].shape}, this render is {shape}")
        a_half, b_half = ((mine * spp + old * a.add_spp) / (spp + a.add_spp) for mine, old in zip((a_half, b_half), earlier))
        spp += a.add_spp
    mean = (a_half + b_half) / 2
    bad = int((~np.isfinite(mean)).sum())
    write_exr(a.out, mean)
    if a.keep_halves:
        import os
        stem = os.path.join(a.keep_halves, os.path.basename(a.out)[:-4])
        write_exr(stem + ".half-a.exr", a_half)
        write_exr(stem + ".half-b.exr", b_half)

    def noise(r0=0, r1=None, c0=0, c1=None):
        d = (a_half - b_half)[r0:r1, c0:c1]
        return float(np.sqrt((d * d).mean()) / 2)

    info = {
        "scene": a.scene, "width": a.width, "height": a.height, "spp": spp, "passes": passes,
        "seconds": round(seconds, 1), "mitsuba": mi.__version__, "variant": a.variant,
        "noise_rmse": noise(), "mean": float(mean.mean()), "nonfinite": bad,
        "windows": {},
    }
    if a.add:
        info["added"] = {"halves": a.add, "spp": a.add_spp, "seed": a.seed}
    if a.crop:
        info["crop"] = {"rows": [r0, r1], "cols": [c0, c1]}
    for w in a.window:
        name, (r0, r1, c0, c1) = parse_window(w)
        info["windows"][name] = {"rows": [r0, r1], "cols": [c0, c1], "noise_rmse": noise(r0, r1, c0, c1),
                                 "mean": float(mean[r0:r1, c0:c1].mean())}
    with open(a.out[:-4] + ".json" if a.out.endswith(".exr") else a.out + ".json", "w") as f:
        json.dump(info, f, indent=1)
    print(json.dumps(info))


if __name__ == "__main__":
    sys.exit(main())
