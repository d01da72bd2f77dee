//! Pearson's χ² goodness-of-fit test of a direction sampler against its pdf,
//! as Nori's and Mitsuba 3's test suites do it: sampled directions are
//! binned in cells of (cos θ, φ) over the sphere; each cell's expected
//! count is N times the pdf integrated over it (adaptive Simpson, the
//! measure dω = d cos θ dφ); the samples the sampler declines (`None`)
//! are one more cell, expected N minus the integral over the sphere; cells
//! expecting fewer than 5 are pooled; the statistic's p-value, on
//! (cells - 1) degrees of freedom, is compared with a level Šidák-corrected
//! for the number of tests a suite runs.

use glam::{Vec2, Vec3};
use std::f64::consts::PI;

/// One χ² test's setting.
#[derive(Clone, Copy, Debug)]
pub struct Chi2 {
    pub cos_bins: usize,
    pub phi_bins: usize,
    pub samples: usize,
    /// The family-wise level; each test is held to 1 - (1 - level)^(1 / tests).
    pub level: f64,
    pub tests: usize,
}

impl Default for Chi2 {
    fn default() -> Self {
        Chi2 { cos_bins: 16, phi_bins: 32, samples: 400_000, level: 0.01, tests: 1 }
    }
}

/// What a test found.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// The level this one test was held to.
    pub threshold: f64,
    /// The integral of the pdf over the sphere.
    pub pdf_mass: f64,
}

impl Outcome {
    pub fn passed(&self) -> bool {
        self.p_value > self.threshold
    }
}

impl Chi2 {
    /// Runs `sample` `samples` times and bins what it returns against
    /// `pdf` (per unit solid angle over the whole sphere).
    pub fn run(&self, mut sample: impl FnMut() -> Option<Vec3>, pdf: impl Fn(Vec3) -> f64) -> Outcome {
        let (nc, np) = (self.cos_bins, self.phi_bins);
        let mut observed = vec![0f64; nc * np + 1];
        for _ in 0..self.samples {
            match sample() {
                Some(w) => observed[self.cell(w)] += 1.0,
                None => observed[nc * np] += 1.0,
            }
        }
        let mut expected = vec![0f64; nc * np + 1];
        let mut mass = 0.0;
        for i in 0..nc {
            for j in 0..np {
                let (c0, c1) = (-1.0 + 2.0 * i as f64 / nc as f64, -1.0 + 2.0 * (i + 1) as f64 / nc as f64);
                let (p0, p1) = (2.0 * PI * j as f64 / np as f64, 2.0 * PI * (j + 1) as f64 / np as f64);
                let f = |c: f64, phi: f64| {
                    let s = (1.0 - c * c).max(0.0).sqrt();
                    pdf(Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32))
                };
                let integral = simpson_2d(&f, c0, c1, p0, p1);
                mass += integral;
                expected[i * np + j] = integral * self.samples as f64;
            }
        }
        expected[nc * np] = ((1.0 - mass) * self.samples as f64).max(0.0);
        self.pearson(&observed, &expected, mass)
    }

    /// As [`Self::run`] for a sampler of points of the unit square, binned
    /// in `cos_bins` x `phi_bins` cells, against `pdf` (per unit area of
    /// the square).
    pub fn run_square(&self, mut sample: impl FnMut() -> Option<Vec2>, pdf: impl Fn(f64, f64) -> f64) -> Outcome {
        let (nx, ny) = (self.cos_bins, self.phi_bins);
        let mut observed = vec![0f64; nx * ny + 1];
        for _ in 0..self.samples {
            match sample() {
                Some(p) => {
                    let i = ((p.x.clamp(0.0, 1.0) as f64 * nx as f64) as usize).min(nx - 1);
                    let j = ((p.y.clamp(0.0, 1.0) as f64 * ny as f64) as usize).min(ny - 1);
                    observed[i * ny + j] += 1.0;
                }
                None => observed[nx * ny] += 1.0,
            }
        }
        let mut expected = vec![0f64; nx * ny + 1];
        let mut mass = 0.0;
        for i in 0..nx {
            for j in 0..ny {
                let (x0, x1) = (i as f64 / nx as f64, (i + 1) as f64 / nx as f64);
                let (y0, y1) = (j as f64 / ny as f64, (j + 1) as f64 / ny as f64);
                let integral = simpson_2d(&pdf, x0, x1, y0, y1);
                mass += integral;
                expected[i * ny + j] = integral * self.samples as f64;
            }
        }
        expected[nx * ny] = ((1.0 - mass) * self.samples as f64).max(0.0);
        self.pearson(&observed, &expected, mass)
    }

    /// Pearson's test of `observed` counts against `expected` ones (the
    /// same total), cells expecting fewer than 5 pooled; `mass` is
    /// reported as the pdf's integral.
    pub fn pearson(&self, observed: &[f64], expected: &[f64], mass: f64) -> Outcome {
        // Pool the cells expecting fewer than 5, smallest first, until the
        // pool itself expects 5 (or holds them all).
        let mut order: Vec<usize> = (0..expected.len()).collect();
        order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
        let (mut pool_e, mut pool_o, mut statistic, mut cells) = (0.0, 0.0, 0.0, 0usize);
        for &k in &order {
            if expected[k] < 5.0 || pool_e > 0.0 && pool_e < 5.0 {
                pool_e += expected[k];
                pool_o += observed[k];
            } else {
                statistic += (observed[k] - expected[k]).powi(2) / expected[k];
                cells += 1;
            }
        }
        if pool_e > 0.0 {
            statistic += (pool_o - pool_e).powi(2) / pool_e;
            cells += 1;
        } else if pool_o > 0.0 {
            // Samples where the pdf says none can be.
            statistic = f64::INFINITY;
        }
        let dof = cells.saturating_sub(1).max(1);
        let p_value = if statistic.is_finite() { gamma_q(dof as f64 / 2.0, statistic / 2.0) } else { 0.0 };
        let threshold = 1.0 - (1.0 - self.level).powf(1.0 / self.tests as f64);
        Outcome { statistic, dof, p_value, threshold, pdf_mass: mass }
    }

    /// A test of weighted samples: `sample` returns a direction and its
    /// weight, whose sum over a cell of the sphere must have the mean
    /// `samples` times the integral of `density` over the cell (a photon's
    /// direction and its power, against the light's radiant intensity).
    pub fn run_weighted(
        &self,
        mut sample: impl FnMut() -> Option<(Vec3, f64)>,
        density: impl Fn(Vec3) -> f64,
    ) -> Outcome {
        let (nc, np) = (self.cos_bins, self.phi_bins);
        let integral = |k: usize| {
            let (i, j) = (k / np, k % np);
            let (c0, c1) = (-1.0 + 2.0 * i as f64 / nc as f64, -1.0 + 2.0 * (i + 1) as f64 / nc as f64);
            let (p0, p1) = (2.0 * PI * j as f64 / np as f64, 2.0 * PI * (j + 1) as f64 / np as f64);
            let f = |c: f64, phi: f64| {
                let s = (1.0 - c * c).max(0.0).sqrt();
                density(Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32))
            };
            simpson_2d(&f, c0, c1, p0, p1)
        };
        self.run_weighted_cells(nc * np, || sample().map(|(w, x)| (self.cell(w), x)), integral)
    }

    /// As [`Self::run_weighted`] for points of the unit square (`density`
    /// per unit area of the square).
    pub fn run_weighted_square(
        &self,
        mut sample: impl FnMut() -> Option<(Vec2, f64)>,
        density: impl Fn(f64, f64) -> f64,
    ) -> Outcome {
        let (nx, ny) = (self.cos_bins, self.phi_bins);
        let cell = |p: Vec2| {
            let i = ((p.x.clamp(0.0, 1.0) as f64 * nx as f64) as usize).min(nx - 1);
            let j = ((p.y.clamp(0.0, 1.0) as f64 * ny as f64) as usize).min(ny - 1);
            i * ny + j
        };
        let integral = |k: usize| {
            let (i, j) = ((k / ny) as f64, (k % ny) as f64);
            simpson_2d(&density, i / nx as f64, (i + 1.0) / nx as f64, j / ny as f64, (j + 1.0) / ny as f64)
        };
        self.run_weighted_cells(nx * ny, || sample().map(|(p, x)| (cell(p), x)), integral)
    }

    /// The weighted test over `cells`: each cell's sum of weights against
    /// `samples` times its `integral`, its deviation divided by the sum's
    /// sampled variance (Σ w² less the mean's share); the sum of squares is
    /// χ²-distributed on the number of cells (cells with fewer than 20
    /// hits pooled). Weight where the density says none can be fails, as
    /// does a large expected share where nothing came.
    pub fn run_weighted_cells(
        &self,
        cells: usize,
        mut sample: impl FnMut() -> Option<(usize, f64)>,
        integral: impl Fn(usize) -> f64,
    ) -> Outcome {
        let (mut sum, mut sum2, mut hits) = (vec![0f64; cells], vec![0f64; cells], vec![0u64; cells]);
        for _ in 0..self.samples {
            if let Some((c, weight)) = sample() {
                sum[c] += weight;
                sum2[c] += weight * weight;
                hits[c] += 1;
            }
        }
        let n = self.samples as f64;
        let (mut statistic, mut dof, mut mass) = (0.0, 0usize, 0.0);
        let (mut pool_o, mut pool_e, mut pool_v, mut pool_hits) = (0.0, 0.0, 0.0, 0u64);
        for k in 0..cells {
            let integral = integral(k);
            mass += integral;
            let (o, e) = (sum[k], integral * n);
            if e <= 0.0 && o > 0.0 {
                statistic = f64::INFINITY;
            }
            let v = (sum2[k] - o * o / n).max(0.0);
            if hits[k] >= 20 && v > 0.0 {
                statistic += (o - e).powi(2) / v;
                dof += 1;
            } else {
                (pool_o, pool_e, pool_v, pool_hits) = (pool_o + o, pool_e + e, pool_v + v, pool_hits + hits[k]);
            }
        }
        if pool_hits >= 20 && pool_v > 0.0 {
            statistic += (pool_o - pool_e).powi(2) / pool_v;
            dof += 1;
        } else if pool_e > 1e-3 * mass * n {
            statistic = f64::INFINITY;
        }
        let dof = dof.max(1);
        let p_value = if statistic.is_finite() { gamma_q(dof as f64 / 2.0, statistic / 2.0) } else { 0.0 };
        let threshold = 1.0 - (1.0 - self.level).powf(1.0 / self.tests as f64);
        Outcome { statistic, dof, p_value, threshold, pdf_mass: mass }
    }

    fn cell(&self, w: Vec3) -> usize {
        let c = (w.z as f64).clamp(-1.0, 1.0);
        let i = (((c + 1.0) / 2.0 * self.cos_bins as f64) as usize).min(self.cos_bins - 1);
        let mut phi = (w.y as f64).atan2(w.x as f64);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let j = ((phi / (2.0 * PI) * self.phi_bins as f64) as usize).min(self.phi_bins - 1);
        i * self.phi_bins + j
    }
}

/// ∫∫ f over [x0, x1] x [y0, y1], adaptive Simpson in both variables.
fn simpson_2d(f: &impl Fn(f64, f64) -> f64, x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    let inner = |x: f64| adaptive_simpson(&|y| f(x, y), y0, y1);
    adaptive_simpson(&inner, x0, x1)
}

/// Relative tolerance and depth of the adaptive integration: far below
/// the counts' noise, and bounded in cost where a lobe is sharp.
const REL_EPS: f64 = 1e-5;
const DEPTH: u32 = 7;

fn adaptive_simpson(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    // Start from eight panels: a sharp lobe between three points would be
    // missed.
    const PANELS: usize = 8;
    let width = (b - a) / PANELS as f64;
    let panels: Vec<(f64, f64, f64, f64, f64, f64)> = (0..PANELS)
        .map(|k| {
            let (lo, hi) = (a + k as f64 * width, a + (k + 1) as f64 * width);
            let (fl, fm, fh) = (f(lo), f(0.5 * (lo + hi)), f(hi));
            (lo, hi, fl, fm, fh, width / 6.0 * (fl + 4.0 * fm + fh))
        })
        .collect();
    let rough: f64 = panels.iter().map(|p| p.5.abs()).sum();
    let eps = REL_EPS * rough / PANELS as f64 + 1e-14;
    panels.into_iter().map(|(lo, hi, fl, fm, fh, s)| simpson_step(f, lo, hi, fl, fm, fh, s, eps, DEPTH)).sum()
}

#[allow(clippy::too_many_arguments)]
fn simpson_step(
    f: &impl Fn(f64) -> f64,
    a: f64,
    b: f64,
    fa: f64,
    fm: f64,
    fb: f64,
    whole: f64,
    eps: f64,
    depth: u32,
) -> f64 {
    let m = 0.5 * (a + b);
    let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
    let (flm, frm) = (f(lm), f(rm));
    let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    let delta = left + right - whole;
    if depth == 0 || delta.abs() <= 15.0 * eps {
        return left + right + delta / 15.0;
    }
    simpson_step(f, a, m, fa, flm, fm, left, eps / 2.0, depth - 1)
        + simpson_step(f, m, b, fm, frm, fb, right, eps / 2.0, depth - 1)
}

/// The regularised upper incomplete gamma function Q(a, x): the chance a
/// χ² variable of 2a degrees of freedom exceeds 2x. A series below a + 1,
/// Lentz's continued fraction above (the textbook split).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let log_prefix = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        let (mut term, mut sum, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * log_prefix.exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        log_prefix.exp() * h
    }
}

/// ln Γ(x) for x > 0: Lanczos' approximation (g = 7, nine terms).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut s = C[0];
    for (i, c) in C.iter().enumerate().skip(1) {
        s += c / (x + i as f64);
    }
    let t = x + 7.5;
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + s.ln()
}
