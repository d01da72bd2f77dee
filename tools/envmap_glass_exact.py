#!/usr/bin/env python3
"""Suite scene 11 (11-envmap-glass) traced exactly where the sun is seen
through the ball: an independent check of both renderers there.

usage: envmap_glass_exact.py MAP.exr [--rows R0:R1] [--cols C0:C1] [--n N]
                             [--mitsuba-offset X,Y,Z SCALE] [--compare IMG.exr ...]

MAP.exr is the map as `photonmap export --mitsuba` writes it (EXPORT-meshes/
envmap001.exr). For each pixel of the 200 x 200 image in the window (half-
open rows and columns), N x N camera rays at the midpoints of the pixel's
strata (a box filter, the suite's and the export's) are traced in float64:
the look-at camera of scenes/suite/11-envmap-glass.toml, the analytic ball
(centre (0, 0.3, 0.501), radius 0.5, index 1.5 in air of 1.0, as the TOML
and the export say), every Fresnel branch followed with its weight (the
unpolarised dielectric Fresnel equations; total internal reflection) until
it is below 1e-7 (or after 64 events), and the map looked up bilinearly as Mitsuba 3's envmap
defines it (texel centres at u = (x + 1/2) / W, rows at v = y / (H - 1);
src/envmap.rs), turned by the scene's rotation about x by 90 degrees.
Branches that end on the floor are not valued: their weight is printed
(the floor reads under 2 here, so it adds under 1 to a streak pixel).

--mitsuba-offset X,Y,Z SCALE starts each ray leaving the ball where
Mitsuba 3 starts it (Interaction::offset_p, include/mitsuba/render/
interaction.h): moved off the surface along the normal by (1 + the largest
|coordinate| of the point in the export's frame) times 1500 float32
epsilons, the export's frame being (p - (X, Y, Z)) x SCALE, its placement
(`photonmap export --origin X,Y,Z --scale SCALE`; the default is the eye,
0.2,-3.4,1.7 and 1).

Prints the green channel of the window, the floor's weight, and for each
--compare image (a 200 x 200 render, or a crop of exactly the window) the
pixels and its RMSE against the exact values over the window's pixels
that see the sun (above 5)."""
import argparse
import numpy as np

EYE = np.array([0.2, -3.4, 1.7])
TARGET = np.array([-0.15, 0.05, 0.3])
UP = np.array([0.0, 0.0, 1.0])
VFOV = 36.0
SIZE = 200
CENTRE = np.array([0.0, 0.3, 0.501])
RADIUS = 0.5
IOR = 1.5
RAY_EPSILON = 2.0 ** -24 * 1500


def read_exr(path):
    import OpenEXR
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            return np.array(ch["RGB"].pixels, dtype=np.float64)
        return np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)


def lookup(image, d):
    """Bilinear radiance arriving from world directions d (rows)."""
    mh, mw, _ = image.shape
    # The map's +y is the scene's +z (a rotation about x by 90 degrees).
    lx, ly, lz = d[:, 0], d[:, 2], -d[:, 1]
    u = np.arctan2(lx, -lz) / (2 * np.pi)
    u -= np.floor(u)
    v = np.arccos(np.clip(ly, -1, 1)) / np.pi
    x, y = u * mw - 0.5, v * (mh - 1)
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    x0, y0 = x0.astype(int), y0.astype(int)

    def t(xx, yy):
        return image[np.clip(yy, 0, mh - 1), np.mod(xx, mw)]

    top = t(x0, y0) * (1 - fx) + t(x0 + 1, y0) * fx
    bottom = t(x0, y0 + 1) * (1 - fx) + t(x0 + 1, y0 + 1) * fx
    return top * (1 - fy) + bottom * fy


def on_floor(o, d, tmax):
    """Whether each ray meets the 10 x 10 floor (z = 0) before tmax."""
    down = d[:, 2] < 0
    t = np.where(down, -o[:, 2] / np.where(down, d[:, 2], -1.0), np.inf)
    p = o + np.where(np.isfinite(t), t, 0.0)[:, None] * d
    return down & (t > 0) & (t < tmax) & (np.abs(p[:, 0]) <= 5) & (np.abs(p[:, 1]) <= 5)


def trace(image, o, d, pix, npix, offset):
    sky, floor = np.zeros((npix, 3)), np.zeros(npix)
    wt = np.ones(len(o))
    inside = np.zeros(len(o), bool)
    # Rays that enter at grazing incidence creep along the inside near the
    # critical angle, each bounce losing little: cut after 64 events (the
    # weight left is under 1e-4 of a streak pixel's).
    for _ in range(64):
        if not len(o):
            break
        oc = o - CENTRE
        b = np.einsum("ij,ij->i", oc, d)
        disc = b * b - (np.einsum("ij,ij->i", oc, oc) - RADIUS * RADIUS)
        root = np.sqrt(np.maximum(disc, 0.0))
        # A ray inside meets the far root; one outside the near root, only
        # if it comes towards the ball (it may start on it, leaving it).
        t = np.where(inside, -b + root, -b - root)
        hit = inside | ((disc > 0) & (b < 0) & (t > 0))
        t = np.where(hit, t, np.inf)
        floored = ~inside & on_floor(o, d, t)
        np.add.at(floor, pix[floored], wt[floored])
        away = ~hit & ~floored
        np.add.at(sky, pix[away], wt[away, None] * lookup(image, d[away]))
        keep = hit & ~floored
        o, d, wt, pix, inside, t = o[keep], d[keep], wt[keep], pix[keep], inside[keep], t[keep]
        # On the sphere, as Mitsuba puts it (its normal times the radius
        # plus the centre): a grazing hit's root is off by ~1e-16 / root.
        n = o + t[:, None] * d - CENTRE
        n /= np.linalg.norm(n, axis=1)[:, None]
        p = CENTRE + RADIUS * n
        facing = np.where(inside[:, None], -n, n)
        cosi = np.clip(-np.einsum("ij,ij->i", d, facing), 0.0, 1.0)
        eta = np.where(inside, 1 / IOR, IOR)
        sin2 = (1 - cosi * cosi) / (eta * eta)
        cost = np.sqrt(np.maximum(0.0, 1 - sin2))
        rs = (cosi - eta * cost) / (cosi + eta * cost)
        rp = (eta * cosi - cost) / (eta * cosi + cost)
        fres = np.where(sin2 >= 1, 1.0, 0.5 * (rs * rs + rp * rp))
        dr = d + 2 * cosi[:, None] * facing
        dt = d / eta[:, None] + (cosi / eta - cost)[:, None] * facing
        dt /= np.linalg.norm(dt, axis=1)[:, None]
        starts = []
        for nd in (dr, dt):
            if offset:
                origin, scale = offset
                mag = (1 + np.abs((p - origin) * scale).max(axis=1)) * RAY_EPSILON / scale
                starts.append(p + (np.sign(np.einsum("ij,ij->i", n, nd)) * mag)[:, None] * n)
            else:
                starts.append(p)
        o, d = np.concatenate(starts), np.concatenate([dr, dt])
        wt = np.concatenate([wt * fres, wt * (1 - fres)])
        pix, inside = np.concatenate([pix, pix]), np.concatenate([inside, ~inside])
        live = wt > 1e-7
        o, d, wt, pix, inside = o[live], d[live], wt[live], pix[live], inside[live]
    return sky, floor


def span(text):
    a, b = (int(v) for v in text.split(":"))
    return a, b


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("map")
    ap.add_argument("--rows", type=span, default=(108, 114))
    ap.add_argument("--cols", type=span, default=(90, 101))
    ap.add_argument("--n", type=int, default=256)
    ap.add_argument("--mitsuba-offset", nargs=2, metavar=("X,Y,Z", "SCALE"))
    ap.add_argument("--compare", nargs="*", default=[])
    a = ap.parse_args()
    image = read_exr(a.map)
    offset = None
    if a.mitsuba_offset:
        offset = (np.array([float(v) for v in a.mitsuba_offset[0].split(",")]), float(a.mitsuba_offset[1]))
    (r0, r1), (c0, c1) = a.rows, a.cols
    fwd = (TARGET - EYE) / np.linalg.norm(TARGET - EYE)
    right = np.cross(fwd, UP)
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    half = np.tan(np.radians(VFOV) / 2)
    k = (np.arange(a.n) + 0.5) / a.n
    sx, sy = (g.ravel() for g in np.meshgrid(k, k))
    ncol = c1 - c0
    exact = np.zeros((r1 - r0, ncol, 3))
    floor = np.zeros((r1 - r0, ncol))
    for i, row in enumerate(range(r0, r1)):
        x = (np.repeat(np.arange(c0, c1), a.n * a.n) + np.tile(sx, ncol)) / SIZE
        y = (row + np.tile(sy, ncol)) / SIZE
        d = fwd + (2 * x - 1)[:, None] * half * right - (2 * y - 1)[:, None] * half * up
        d /= np.linalg.norm(d, axis=1)[:, None]
        pix = np.repeat(np.arange(ncol), a.n * a.n)
        sky, fl = trace(image, np.tile(EYE, (len(d), 1)), d, pix, ncol, offset)
        exact[i], floor[i] = sky / (a.n * a.n), fl / (a.n * a.n)
    np.set_printoptions(linewidth=200, precision=1, suppress=True)
    print(f"rows {r0}:{r1}, columns {c0}:{c1}, {a.n}^2 rays a pixel; green, without the floor:")
    print(exact[..., 1])
    print("the floor's weight:")
    print(floor)
    sun = exact[..., 1] > 5
    for path in a.compare:
        img = read_exr(path)
        if img.shape[:2] == (SIZE, SIZE):
            img = img[r0:r1, c0:c1]
        if img.shape[:2] != exact.shape[:2]:
            raise SystemExit(f"{path}: {img.shape[:2]}, neither {SIZE}^2 nor the window")
        err = (img[..., :3] - exact)[sun]
        print(f"{path}: RMSE against the exact values over the {sun.sum()} pixels that see the sun "
              f"{np.sqrt((err * err).mean()):.3f}")
        print(img[..., 1])


if __name__ == "__main__":
    main()
