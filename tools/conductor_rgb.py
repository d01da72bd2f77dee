#!/usr/bin/env python3
"""Writes src/material/conductors.rs: the RGB eta and k of Mitsuba 3's
named conductors, computed from a mitsuba-data checkout's ior/*.spd files
the way Mitsuba's RGB variants compute them.

Mitsuba reads a named conductor's two spectra (include/mitsuba/render/ior.h,
`complex_ior_from_file`) and in an RGB variant turns each into a colour with
`spectrum_list_to_srgb(wavelengths, values, bounded=false, d65=false)`
(src/core/spectrum.cpp): 1000 evenly spaced wavelengths over the CIE tables'
360-830 nm, the spectrum linearly interpolated between its samples and zero
outside them, weighted by the CIE 1931 colour-matching functions (read from
their 5 nm tables as single-precision numbers and interpolated), scaled by
(830 - 360) / (106.75... * 1000), turned into linear sRGB and clamped at
zero. The colour-matching tables are parsed from src/scene/mitsuba/cie.rs,
the same numbers the renderer's spectrum conversion uses.

Usage:
    python3 tools/conductor_rgb.py MITSUBA_DATA_DIR [OUTPUT.rs]

MITSUBA_DATA_DIR holds ior/NAME.eta.spd and ior/NAME.k.spd (the
mitsuba-data repository). OUTPUT defaults to src/material/conductors.rs
beside this tool.
"""

import bisect
import os
import re
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
CIE_RS = os.path.join(HERE, "..", "src", "scene", "mitsuba", "cie.rs")
DEFAULT_OUT = os.path.join(HERE, "..", "src", "material", "conductors.rs")

CIE_MIN, CIE_MAX, CIE_SAMPLES = 360.0, 830.0, 95
Y_NORMALIZATION = 1.0 / 106.7502593994140625
# XYZ to linear sRGB, the matrix of Mitsuba's xyz_to_srgb (and of spectrum.rs).
XYZ_TO_SRGB = [
    [3.240479, -1.537150, -0.498535],
    [-0.969256, 1.875991, 0.041556],
    [0.055648, -0.204043, 1.057311],
]


def f32(x):
    return struct.unpack("f", struct.pack("f", x))[0]


def cie_tables(path=CIE_RS):
    """The X, Y, Z tables of cie.rs, rounded to single precision as
    Mitsuba stores them."""
    text = open(path, encoding="utf-8").read()
    tables = {}
    for name in ("X", "Y", "Z"):
        m = re.search(r"pub const %s: \[f64; SAMPLES\] = \[(.*?)\];" % name, text, re.S)
        if not m:
            sys.exit(f"{path}: no table {name}")
        values = [f32(float(v)) for v in m.group(1).replace("\n", " ").split(",") if v.strip()]
        if len(values) != CIE_SAMPLES:
            sys.exit(f"{path}: table {name} has {len(values)} values, expected {CIE_SAMPLES}")
        tables[name] = values
    return tables["X"], tables["Y"], tables["Z"]


def read_spd(path):
    """Wavelength and value pairs, '#' starting a comment, as Mitsuba's
    spectrum_from_file reads them; also the comment lines."""
    wavelengths, values, comments = [], [], []
    for n, line in enumerate(open(path, encoding="utf-8", errors="replace"), 1):
        body, _, comment = line.partition("#")
        if _:
            comments.append(comment.strip())
        words = body.split()
        if not words:
            continue
        if len(words) != 2:
            sys.exit(f"{path}:{n}: expected 'wavelength value', got {line.strip()!r}")
        wavelengths.append(float(words[0]))
        values.append(float(words[1]))
    if len(wavelengths) < 2 or any(b <= a for a, b in zip(wavelengths, wavelengths[1:])):
        sys.exit(f"{path}: needs two or more increasing wavelengths")
    return wavelengths, values, comments


def spectrum_list_to_srgb(wavelengths, values, tables):
    """Mitsuba's spectrum_list_to_srgb with bounded=false and d65=false."""
    steps = 1000
    xyz = [0.0, 0.0, 0.0]
    for i in range(steps):
        w = CIE_MIN + (i / (steps - 1)) * (CIE_MAX - CIE_MIN)
        if w < wavelengths[0] or w > wavelengths[-1]:
            continue
        k = min(max(bisect.bisect_right(wavelengths, w) - 1, 0), len(wavelengths) - 2)
        w0, w1, v0, v1 = wavelengths[k], wavelengths[k + 1], values[k], values[k + 1]
        v = ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1)
        t = (w - CIE_MIN) * ((CIE_SAMPLES - 1) / (CIE_MAX - CIE_MIN))
        i0 = min(max(int(t), 0), CIE_SAMPLES - 2)
        f = t - i0
        for c in range(3):
            xyz[c] += ((1.0 - f) * tables[c][i0] + f * tables[c][i0 + 1]) * v
    scale = (CIE_MAX - CIE_MIN) * Y_NORMALIZATION / steps
    xyz = [c * scale for c in xyz]
    rgb = [sum(XYZ_TO_SRGB[r][c] * xyz[c] for c in range(3)) for r in range(3)]
    return [max(c, 0.0) for c in rgb]


def source_of(comments):
    """The data's origin as the .spd header states it, on one line."""
    lines = [c.lstrip(";").strip() for c in comments]
    skip = ("Lambda", "data from www.luxpop.com")
    lines = [l for l in lines if l and not l.startswith(skip) and not set(l) <= set("-")]
    return " ".join(lines)


def rust_f32(x):
    """The shortest decimal that reads back as the same f32."""
    x = f32(x)
    for digits in range(1, 10):
        text = "%.*g" % (digits, x)
        if f32(float(text)) == x:
            break
    return text if any(c in text for c in ".e") else text + ".0"


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    data = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) == 3 else DEFAULT_OUT
    tables = cie_tables()
    ior = os.path.join(data, "ior")
    names = sorted(f[: -len(".eta.spd")] for f in os.listdir(ior) if f.endswith(".eta.spd"))
    if not names:
        sys.exit(f"{ior}: no *.eta.spd files")
    rows = []
    for name in names:
        eta_w, eta_v, comments = read_spd(os.path.join(ior, name + ".eta.spd"))
        k_w, k_v, _ = read_spd(os.path.join(ior, name + ".k.spd"))
        eta = spectrum_list_to_srgb(eta_w, eta_v, tables)
        k = spectrum_list_to_srgb(k_w, k_v, tables)
        rows.append((name, eta, k, source_of(comments)))
    with open(out, "w", encoding="utf-8") as f:
        f.write(HEADER)
        f.write(f"pub const NAMED_CONDUCTORS: [(&str, [f32; 3], [f32; 3]); {len(rows)}] = [\n")
        for name, eta, k, source in rows:
            f.write(f"    // {source}\n")
            e = ", ".join(rust_f32(c) for c in eta)
            kk = ", ".join(rust_f32(c) for c in k)
            f.write(f'    ("{name}", [{e}], [{kk}]),\n')
        f.write("];\n")
        f.write(FOOTER)
    print(f"{out}: {len(rows)} conductors")


HEADER = """\
//! Mitsuba 3's named conductors (the `material` parameter of `conductor`
//! and `roughconductor`, src/bsdfs/conductor.cpp) as RGB eta and k, each
//! computed as Mitsuba's RGB variants compute it from the spectra
//! (`spectrum_list_to_srgb(wavelengths, values, bounded = false,
//! d65 = false)`, src/core/spectrum.cpp), so that a named conductor here
//! has the colour it has in Mitsuba's `scalar_rgb`.
//!
//! The spectra are mitsuba-data's ior/NAME.eta.spd and ior/NAME.k.spd, the
//! data PBRT distributes: from the Luxpop database (luxpop.com), after
//! Palik, Handbook of Optical Constants of Solids (Academic Press, 1985,
//! and volume II, 1991) and the atomic scattering factors measured by the
//! Center for X-Ray Optics (CXRO, Berkeley) and the Lawrence Livermore
//! National Laboratory (LLNL). Each row's comment is its file's own note
//! of where its numbers come from. `none`, Mitsuba's perfect mirror, has
//! no spectra and no row.
//!
//! Generated by tools/conductor_rgb.py from a mitsuba-data checkout; do not
//! edit by hand.

use crate::math::Color;

/// Name, eta (r, g, b), k (r, g, b).
#[rustfmt::skip]
"""

FOOTER = """
/// A named conductor's (eta, k) in RGB, or `None` for a name Mitsuba does
/// not define. `none`, the perfect mirror, is no complex index: callers
/// test for it first.
pub fn named_conductor(name: &str) -> Option<(Color, Color)> {
    NAMED_CONDUCTORS.iter().find(|(n, _, _)| *n == name).map(|(_, eta, k)| (Color::from(*eta), Color::from(*k)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gold reflects red more than blue: its eta is far lower in red than
    /// in blue and its k is large; silver's eta is small in every channel.
    #[test]
    fn gold_and_silver_have_their_colours() {
        let (eta, k) = named_conductor("Au").unwrap();
        assert!(eta.x < 0.5 * eta.z, "Au eta {eta}");
        assert!(k.min_element() > 1.5 && k.x > k.z, "Au k {k}");
        let (eta, k) = named_conductor("Ag").unwrap();
        assert!(eta.max_element() < 0.3 && k.min_element() > 2.0, "Ag {eta} {k}");
        assert!(named_conductor("none").is_none() && named_conductor("gold").is_none());
    }

    /// Normal-incidence reflectance ((n-1)^2 + k^2) / ((n+1)^2 + k^2) of
    /// every row is a reflectance, and the metals reflect most. (A channel
    /// may be 0 where the spectrum's colour lies outside sRGB: Mitsuba
    /// clamps it there too.)
    #[test]
    fn every_row_gives_a_reflectance() {
        let mut names: Vec<&str> = NAMED_CONDUCTORS.iter().map(|r| r.0).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), NAMED_CONDUCTORS.len(), "a name twice");
        for (name, eta, k) in NAMED_CONDUCTORS {
            for c in 0..3 {
                let (n, k) = (eta[c], k[c]);
                assert!(n >= 0.0 && k >= 0.0 && n.is_finite() && k.is_finite(), "{name}");
                let r = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
                assert!((0.0..=1.0).contains(&r), "{name} {r}");
            }
        }
        for metal in ["Ag", "Al", "Au", "Cu"] {
            let (n, k) = named_conductor(metal).unwrap();
            let r = ((n - Color::ONE).powf(2.0) + k * k) / ((n + Color::ONE).powf(2.0) + k * k);
            assert!(r.max_element() > 0.9, "{metal} reflects {r}");
        }
    }
}
"""

if __name__ == "__main__":
    main()
