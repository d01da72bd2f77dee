#!/usr/bin/env python3
"""A reference rendered in many independent passes, time-boxed: for a GPU
(Mitsuba's cuda_ad_rgb variant), where a pass of thousands of samples per
pixel takes a fraction of a second and a run must end inside a fixed limit.

usage: mitsuba_passes.py render OUTDIR VARIANT JOB [JOB ...]
       JOB = NAME:SCENE.xml:SPP_PER_PASS:SECONDS:SEED0[:R0,R1,C0,C1]
       mitsuba_passes.py exr OUTDIR NAME OUT.exr [--window R0,R1,C0,C1] [--device TEXT]

`render` renders each job's scene (exported by `photonmap export --mitsuba`)
at 200 x 200, or only the crop R0:R1 (rows), C0:C1 (columns), in passes
of SPP_PER_PASS with seeds SEED0, SEED0 + 1, ... until the next pass would
end after SECONDS. After the first passes and every 10 s it rewrites
OUTDIR/NAME-mean.npy (the running mean) and NAME-var.npy (each pixel's
variance of that mean, from the passes' spread) and OUTDIR/info.json, so
a run stopped early keeps what it did. Its noise, the square root of
the mean of that variance, is the RMSE of the mean image that
tools/mitsuba_reference.py estimates from two halves; from many passes
it is steady where a few heavy-tailed pixels rule the halves' estimate.

`exr` writes a job's mean as OUT.exr and OUT.json in the format of
tools/mitsuba_reference.py (spp, passes, seconds, noise, mean, windows,
crop), for tests/data/suite/. Not a dependency of the project, not run
in CI."""
import json, os, sys, time
import numpy as np


def save(out, name, mean, var_mean):
    for what, arr in (("mean", mean), ("var", np.maximum(np.nan_to_num(var_mean, nan=0.0), 0))):
        tmp = os.path.join(out, f"{name}-{what}.tmp.npy")
        np.save(tmp, arr.astype(np.float32))
        os.replace(tmp, os.path.join(out, f"{name}-{what}.npy"))


def render(out, variant, jobs):
    import mitsuba as mi
    mi.set_variant(variant)
    infos = {}
    for job in jobs:
        parts = job.split(":")
        name, xml_path, per, seconds, seed0 = parts[0], parts[1], int(parts[2]), float(parts[3]), int(parts[4])
        crop = tuple(int(v) for v in parts[5].split(",")) if len(parts) > 5 else None
        mi.file_resolver().prepend(os.path.dirname(os.path.abspath(xml_path)))
        with open(xml_path) as f:
            xml = f.read()
        if crop:
            r0, r1, c0, c1 = crop
            film = '<film type="hdrfilm">'
            if xml.count(film) != 1:
                sys.exit(f"{xml_path}: no single '{film}' to crop")
            xml = xml.replace(film, film + "".join(
                f'<integer name="{k}" value="{v}"/>'
                for k, v in [("crop_offset_x", c0), ("crop_offset_y", r0),
                             ("crop_width", c1 - c0), ("crop_height", r1 - r0)]))
        scene = mi.load_string(xml, spp=per, width=200, height=200)
        s1 = s2 = None
        n, t0, last = 0, time.time(), -1e9
        while True:
            tp = time.time()
            img = np.array(mi.render(scene, spp=per, seed=seed0 + n), dtype=np.float64)[..., :3]
            dt = time.time() - tp
            if s1 is None:
                s1, s2 = np.zeros_like(img), np.zeros_like(img)
            s1 += img
            s2 += img * img
            n += 1
            mean = s1 / n
            var_mean = (s2 / n - mean * mean) / (n - 1) if n > 1 else np.full_like(mean, np.nan)
            elapsed = time.time() - t0
            done = elapsed + 1.1 * dt > seconds
            if n <= 2 or elapsed - last > 10 or done:
                save(out, name, mean, var_mean)
                infos[name] = {"xml": os.path.basename(xml_path), "variant": variant, "mitsuba": mi.__version__, "passes": n, "spp_per_pass": per,
                               "spp": n * per, "seconds": round(elapsed, 2), "seed0": seed0, "crop": crop,
                               "mean": float(mean.mean()),
                               "noise_rmse": float(np.sqrt(np.nanmean(var_mean))) if n > 1 else None,
                               "nonfinite": int((~np.isfinite(mean)).sum())}
                with open(os.path.join(out, "info.json"), "w") as f:
                    json.dump(infos, f, indent=1)
                last = elapsed
                print(f"{name}: pass {n}, {n * per} spp, {elapsed:.0f} s, noise {infos[name]['noise_rmse']}", flush=True)
            if done:
                break


def exr(out, name, target, window, device):
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from mitsuba_reference import write_exr
    info = json.load(open(os.path.join(out, "info.json")))[name]
    mean = np.load(os.path.join(out, f"{name}-mean.npy")).astype(np.float64)
    var = np.load(os.path.join(out, f"{name}-var.npy")).astype(np.float64)
    write_exr(target, mean)
    d = {"scene": info.get("xml", name), "width": 200, "height": 200, "spp": info["spp"], "passes": info["passes"],
         "seconds": round(info["seconds"], 1), "mitsuba": info["mitsuba"], "variant": info["variant"],
         "device": device, "noise_rmse": float(np.sqrt(var.mean())),
         "noise_estimate": "per-pixel variance of the mean from the spread of the passes' images (independent seeds)",
         "mean": float(mean.mean()), "nonfinite": int((~np.isfinite(mean)).sum()), "windows": {},
         "seed": info["seed0"]}
    if window:
        r0, r1, c0, c1 = window
        d["windows"]["caustic"] = {"rows": [r0, r1], "cols": [c0, c1],
                                   "noise_rmse": float(np.sqrt(var[r0:r1, c0:c1].mean())),
                                   "mean": float(mean[r0:r1, c0:c1].mean())}
    if info["crop"]:
        r0, r1, c0, c1 = info["crop"]
        d["crop"] = {"rows": [r0, r1], "cols": [c0, c1]}
    with open(target[:-4] + ".json", "w") as f:
        json.dump(d, f, indent=1)
    print(json.dumps(d))


def main():
    a = sys.argv[1:]
    if len(a) >= 4 and a[0] == "render":
        return render(a[1], a[2], a[3:])
    if len(a) >= 4 and a[0] == "exr":
        opt = lambda f: a[a.index(f) + 1] if f in a else None
        w = opt("--window")
        return exr(a[1], a[2], a[3], tuple(int(v) for v in w.split(",")) if w else None, opt("--device") or "")
    sys.exit(__doc__)


if __name__ == "__main__":
    sys.exit(main())
