//! The error of a render of the default scene against a reference, exactly
//! as `shared/refs/metrics.py` computes it (tests check both agree): an 800²
//! image is reduced to 200² by averaging 4 x 4 blocks, then compared with the
//! 200² reference over all pixels and channels, and inside the caustic
//! window (rows 173..193, columns 126..157 of the 200² image).

use crate::film::Film;
use crate::math::Color;

/// Caustic window in 200² pixel coordinates: [row0, row1) x [col0, col1).
pub const CAUSTIC_WINDOW_200: (u32, u32, u32, u32) = (173, 193, 126, 157);

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    pub rmse: f64,
    pub relmse: f64,
    pub caustic_rmse: f64,
    pub mean_x: f64,
    pub mean_r: f64,
    pub caustic_mean_x: f64,
    pub caustic_mean_r: f64,
    pub nan_count: u64,
}

/// Averages `f` x `f` blocks.
pub fn box_down(film: &Film, f: u32) -> Film {
    let (w, h) = (film.width / f, film.height / f);
    let mut out = Film::new(w, h);
    for r in 0..h {
        for c in 0..w {
            let mut s = glam::DVec3::ZERO;
            for dr in 0..f {
                for dc in 0..f {
                    s += film.get(c * f + dc, r * f + dr).as_dvec3();
                }
            }
            out.pixels[(r * w + c) as usize] = (s / (f * f) as f64).as_vec3();
        }
    }
    out
}

/// Compares `test` (any multiple of the reference's size) with `reference`.
/// Non-finite test values are counted and treated as 0, as metrics.py does.
pub fn compare(test: &Film, reference: &Film) -> Option<Metrics> {
    if reference.width == 0
        || !test.width.is_multiple_of(reference.width)
        || !test.height.is_multiple_of(reference.height)
    {
        return None;
    }
    let f = test.width / reference.width;
    if test.height / reference.height != f {
        return None;
    }
    let nan_count = test.pixels.iter().flat_map(|c| c.to_array()).filter(|v| !v.is_finite()).count() as u64;
    let clean = Film {
        width: test.width,
        height: test.height,
        pixels: test
            .pixels
            .iter()
            .map(|c| Color::from_array(c.to_array().map(|v| if v.is_finite() { v } else { 0.0 })))
            .collect(),
    };
    let x = if f == 1 { clean } else { box_down(&clean, f) };
    let s = reference.width / 200;
    let (r0, r1, c0, c1) = CAUSTIC_WINDOW_200;
    let (r0, r1, c0, c1) = (r0 * s, r1 * s, c0 * s, c1 * s);
    let (mut d2, mut rel, mut sx, mut sr) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (mut cd2, mut csx, mut csr, mut cn) = (0.0f64, 0.0f64, 0.0f64, 0u64);
    for row in 0..reference.height {
        for col in 0..reference.width {
            let a = x.get(col, row).as_dvec3();
            let b = reference.get(col, row).as_dvec3();
            for ch in 0..3 {
                let diff = (a[ch] - b[ch]).powi(2);
                d2 += diff;
                rel += diff / (b[ch] * b[ch] + 1e-2);
                sx += a[ch];
                sr += b[ch];
                if (r0..r1).contains(&row) && (c0..c1).contains(&col) {
                    cd2 += diff;
                    csx += a[ch];
                    csr += b[ch];
                    cn += 1;
                }
            }
        }
    }
    let n = (reference.pixels.len() * 3) as f64;
    let cn = cn.max(1) as f64;
    Some(Metrics {
        rmse: (d2 / n).sqrt(),
        relmse: rel / n,
        caustic_rmse: (cd2 / cn).sqrt(),
        mean_x: sx / n,
        mean_r: sr / n,
        caustic_mean_x: csx / cn,
        caustic_mean_r: csr / cn,
        nan_count,
    })
}
