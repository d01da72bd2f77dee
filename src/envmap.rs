//! An environment map: radiance arriving from infinitely far away, read
//! from a latitude-longitude image, as Mitsuba 3's `envmap` defines it
//! (src/emitters/envmap.cpp): in the map's own frame a direction d has
//! u = atan2(d.x, -d.z) / 2π and v = acos(d.y) / π, +y up; the image is
//! looked up bilinearly with texel centres at u = (x + ½) / W, periodic,
//! and, as Mitsuba aligns the rows with the poles, at v = y / (H - 1);
//! `scale` multiplies it.
//!
//! Directions are drawn in proportion to the bilinear interpolation of
//! luminance times sin θ between the texels (the solid angle a row spans
//! shrinks as sin θ): the lattice of texel centres splits the map into
//! cells, a cell is drawn by its integral and a point in it from the
//! bilinear density (pbrt-v4's `SampleBilinear`, by its linear marginal
//! and conditional). The map's radiance is the bilinear interpolation of
//! the same texels, so the density is positive wherever light arrives
//! (but exactly at a pole), and it is exact: the pdf of a direction is
//! the bilinear density at it over 2π² sin θ. ∫ L dω, which a photon's
//! power is a share of, is exact too: within a row the interpolation
//! integrates to the row's mean, and between rows the linear blend times
//! sin θ has a closed form.
//!
//! A second distribution, of the map less its mean luminance, serves the
//! shadow rays that share light with a cosine strategy by MIS (MIS
//! compensation, notes/method.md): the same lattice, other weights.

use crate::film::Film;
use crate::math::Color;
use crate::sampling::{uniform_cone, Discrete};
use glam::{Mat3, Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Debug)]
pub struct EnvMap {
    width: usize,
    height: usize,
    texels: Vec<Color>,
    /// The map's frame in world space (a rotation) and back.
    to_world: Mat3,
    to_local: Mat3,
    /// Per texel, its luminance times sin θ of its row: the density's
    /// values at the lattice's points.
    weights: Vec<f32>,
    /// The cells (between texel centres: `width` along u, `height - 1`
    /// along v) by their integrals; `None` where the map is black (or one
    /// row high), and directions are uniform.
    cells: Option<Discrete>,
    /// The cells' count over the sum of their mean weights: the density
    /// over (u, v) is the bilinear weight times it.
    norm: f32,
    /// ∫ L dω over the sphere, per channel.
    total: Color,
    /// The density of shadow rays whose directions a cosine strategy also
    /// draws (MIS compensation, Karlík et al. 2019, "MIS compensation:
    /// optimizing sampling techniques in multiple importance sampling"):
    /// the map less its mean luminance, floored at zero, as lattice weights
    /// with their cells and norm; the parts no brighter than the mean are
    /// left to the other strategy. `None` where nothing is brighter than
    /// the mean (a uniform map).
    compensated: Option<(Vec<f32>, Discrete, f32)>,
}

/// Luminance of linear sRGB (Rec. 709 weights).
fn luminance(c: Color) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// A point in [0, 1) drawn with density proportional to (1 - x) a + x b
/// (a, b >= 0, not both zero), from uniform `u` (pbrt-v4's SampleLinear).
fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if u == 0.0 && a == 0.0 {
        return 0.0;
    }
    let x = u * (a + b) / (a + ((1.0 - u) * a * a + u * b * b).sqrt());
    x.min(1.0 - f32::EPSILON / 2.0)
}

/// The cells between a lattice's points (`width` periodic along u, `rows`
/// along v) by their integrals, and the cells' count over their sum;
/// `None` where every weight is zero.
fn lattice_cells(weights: &[f32], width: usize, rows: usize) -> (Option<Discrete>, f32) {
    let cell = |k: usize| {
        let (i, j) = (k % width, k / width);
        let w = |x: usize, y: usize| weights[y * width + x % width] as f64;
        0.25 * (w(i, j) + w(i + 1, j) + w(i, j + 1) + w(i + 1, j + 1))
    };
    let sum: f64 = (0..width * rows).map(cell).sum();
    if !(sum > 0.0) {
        return (None, 0.0);
    }
    (Discrete::new((0..width * rows).map(cell)), ((width * rows) as f64 / sum) as f32)
}

impl EnvMap {
    /// `image` scaled by `scale`, its frame `to_world` (orthonormal).
    pub fn new(image: &Film, scale: f32, to_world: Mat3) -> Self {
        let (width, height) = (image.width as usize, image.height as usize);
        let texels: Vec<Color> = image.pixels.iter().map(|c| (*c * scale).max(Color::ZERO)).collect();
        let rows = height.max(2) - 1;
        let sin = |y: usize| (std::f64::consts::PI * y as f64 / rows as f64).sin() as f32;
        let weights: Vec<f32> = (0..width * height).map(|i| luminance(texels[i]) * sin(i / width)).collect();
        let (cells, norm) = if height >= 2 { lattice_cells(&weights, width, rows) } else { (None, 0.0) };
        let mut map = EnvMap {
            width,
            height,
            texels,
            to_world,
            to_local: to_world.transpose(),
            weights,
            cells,
            norm,
            total: Color::ZERO,
            compensated: None,
        };
        map.total = map.integral();
        if height >= 2 {
            let mean = luminance(map.total) / (4.0 * PI);
            let weights: Vec<f32> =
                (0..width * height).map(|i| (luminance(map.texels[i]) - mean).max(0.0) * sin(i / width)).collect();
            let (cells, norm) = lattice_cells(&weights, width, rows);
            map.compensated = cells.map(|c| (weights, c, norm));
        }
        map
    }

    /// ∫ L dω, exactly for the bilinear interpolation: 2π² ∫∫ L sin(πv)
    /// du dv, where each row integrates over u to its mean and two rows
    /// blend linearly in v.
    fn integral(&self) -> Color {
        let (w, h) = (self.width, self.height);
        let mean = |y: usize| {
            self.texels[y * w..(y + 1) * w].iter().fold(glam::DVec3::ZERO, |a, c| a + c.as_dvec3()) / w as f64
        };
        if h < 2 {
            // One row: the lookup is that row everywhere.
            return (mean(0) * 4.0 * std::f64::consts::PI).as_vec3();
        }
        let step = 1.0 / (h - 1) as f64;
        let alpha = std::f64::consts::PI * step;
        let mut total = glam::DVec3::ZERO;
        for j in 0..h - 1 {
            let (t0, t1) = (alpha * j as f64, alpha * (j + 1) as f64);
            // ∫0^1 b sin(α(j + b)) db and ∫0^1 (1 - b) sin(α(j + b)) db.
            let i1 = -t1.cos() / alpha + (t1.sin() - t0.sin()) / (alpha * alpha);
            let i0 = (t0.cos() - t1.cos()) / alpha - i1;
            total += mean(j) * i0 + mean(j + 1) * i1;
        }
        (total * 2.0 * std::f64::consts::PI * std::f64::consts::PI * step).as_vec3()
    }

    /// ∫ L dω over the sphere, per channel.
    pub fn total(&self) -> Color {
        self.total
    }

    /// ∫ L(ω) |ω_k| dω for each world axis k, per channel: with a box's
    /// face areas F_k, Σ F_k times these is the power the map sends
    /// into the box (its shadow across ω has area Σ F_k |ω_k|). By the
    /// midpoint rule on a grid twice as fine as the image: it only
    /// apportions photons among lights, never their estimates.
    pub fn abs_moments(&self) -> [Color; 3] {
        let (nu, nv) = (2 * self.width, 2 * self.height.max(2));
        let mut sum = [glam::DVec3::ZERO; 3];
        for j in 0..nv {
            let v = (j as f32 + 0.5) / nv as f32;
            let w = (PI * v).sin() as f64 * 2.0 * std::f64::consts::PI.powi(2) / (nu * nv) as f64;
            for i in 0..nu {
                let uv = Vec2::new((i as f32 + 0.5) / nu as f32, v);
                let l = self.lookup(uv).as_dvec3() * w;
                let d = self.direction(uv).abs();
                for (k, s) in sum.iter_mut().enumerate() {
                    *s += l * d[k] as f64;
                }
            }
        }
        sum.map(|s| s.as_vec3())
    }

    /// The map's texels (scaled) and its frame, as it was made.
    pub fn image(&self) -> (Film, Mat3) {
        (Film { width: self.width as u32, height: self.height as u32, pixels: self.texels.clone() }, self.to_world)
    }

    /// The radiance image an `envmap` names: OpenEXR, Radiance HDR, or
    /// any image a bitmap texture reads (8-bit images decoded from sRGB,
    /// as Mitsuba does).
    pub fn load(path: &std::path::Path) -> Result<Film, String> {
        let bitmap = crate::texture::Bitmap::load(path, false)?;
        let res = bitmap.resolution();
        let (w, h) = (res.x as u32, res.y as u32);
        let mut pixels = Vec::with_capacity((w * h) as usize);
        let mut nearest = bitmap;
        nearest.filter = crate::texture::Filter::Nearest;
        for y in 0..h {
            for x in 0..w {
                let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                pixels.push(nearest.eval(uv));
            }
        }
        Ok(Film { width: w, height: h, pixels })
    }

    fn uv(&self, world: Vec3) -> Vec2 {
        let d = self.to_local * world;
        let u = d.x.atan2(-d.z) / (2.0 * PI);
        Vec2::new(if u < 0.0 { u + 1.0 } else { u }, d.y.clamp(-1.0, 1.0).acos() / PI)
    }

    fn direction(&self, uv: Vec2) -> Vec3 {
        let (theta, phi) = (uv.y * PI, uv.x * 2.0 * PI);
        let local = Vec3::new(phi.sin() * theta.sin(), theta.cos(), -phi.cos() * theta.sin());
        (self.to_world * local).normalize()
    }

    fn texel(&self, x: i64, y: i64) -> Color {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        self.texels[y * self.width + x]
    }

    fn lookup(&self, uv: Vec2) -> Color {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * (self.height as f32 - 1.0);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0) * (1.0 - fx) + self.texel(x0 + 1, y0) * fx;
        let bottom = self.texel(x0, y0 + 1) * (1.0 - fx) + self.texel(x0 + 1, y0 + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// Radiance arriving from unit world direction `towards` (that is,
    /// travelling along `-towards`).
    #[inline]
    pub fn eval(&self, towards: Vec3) -> Color {
        self.lookup(self.uv(towards))
    }

    /// The cell holding `uv` and the point's place in it: the cell's lower
    /// corner (texel x, row y) and (a, b) in [0, 1]^2.
    fn cell_of(&self, uv: Vec2) -> (usize, usize, f32, f32) {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * (self.height - 1) as f32;
        let (x0, y0) = (x.floor(), y.floor().clamp(0.0, (self.height - 2) as f32));
        let i = (x0 as i64).rem_euclid(self.width as i64) as usize;
        (i, y0 as usize, (x - x0).clamp(0.0, 1.0), (y - y0).clamp(0.0, 1.0))
    }

    /// A unit world direction towards the map and its density (solid
    /// angle), for a point `u` uniform in the unit square.
    pub fn sample(&self, u: Vec2) -> (Vec3, f32) {
        let Some(cells) = &self.cells else {
            let dir = uniform_cone(u, -1.0).normalize();
            return (dir, self.pdf(dir));
        };
        self.sample_lattice(&self.weights, cells, self.norm, u)
    }

    /// The density of [`Self::sample`] at unit world direction `dir`.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        if self.cells.is_none() {
            return 1.0 / (4.0 * PI);
        }
        self.pdf_lattice(&self.weights, self.norm, dir)
    }

    /// Whether [`Self::sample_compensated`] differs from [`Self::sample`]:
    /// some of the map is brighter than its mean.
    pub fn compensates(&self) -> bool {
        self.compensated.is_some()
    }

    /// A direction drawn from the map less its mean (the field
    /// `compensated`), for shadow rays that share the light with a cosine
    /// strategy; [`Self::sample`] where nothing is brighter than the mean.
    pub fn sample_compensated(&self, u: Vec2) -> (Vec3, f32) {
        match &self.compensated {
            Some((weights, cells, norm)) => self.sample_lattice(weights, cells, *norm, u),
            None => self.sample(u),
        }
    }

    /// The density of [`Self::sample_compensated`] at `dir`: zero where
    /// the map is no brighter than its mean.
    pub fn pdf_compensated(&self, dir: Vec3) -> f32 {
        match &self.compensated {
            Some((weights, _, norm)) => self.pdf_lattice(weights, *norm, dir),
            None => self.pdf(dir),
        }
    }

    /// A direction drawn in proportion to the bilinear interpolation of
    /// lattice `weights` between texel centres ([`lattice_cells`]'s
    /// `cells` and `norm`), and its density per solid angle.
    fn sample_lattice(&self, weights: &[f32], cells: &Discrete, norm: f32, u: Vec2) -> (Vec3, f32) {
        let weight = |x: usize, y: usize| weights[y * self.width + x % self.width];
        let (k, rest) = cells.sample(u.x);
        let (i, j) = (k % self.width, k / self.width);
        let (w00, w10) = (weight(i, j), weight(i + 1, j));
        let (w01, w11) = (weight(i, j + 1), weight(i + 1, j + 1));
        let a = sample_linear(rest, w00 + w01, w10 + w11);
        let b = sample_linear(u.y, w00 * (1.0 - a) + w10 * a, w01 * (1.0 - a) + w11 * a);
        let uv =
            Vec2::new(((i as f32 + 0.5 + a) / self.width as f32).fract(), (j as f32 + b) / (self.height - 1) as f32);
        let dir = self.direction(uv);
        // The density where the draw landed (the same as `pdf(dir)` but
        // for rounding in the round trip through the direction).
        let bilinear = (w00 * (1.0 - a) + w10 * a) * (1.0 - b) + (w01 * (1.0 - a) + w11 * a) * b;
        let sin_theta = (uv.y * PI).sin();
        let pdf = if sin_theta > 0.0 { bilinear * norm / (2.0 * PI * PI * sin_theta) } else { 0.0 };
        (dir, pdf)
    }

    /// The density of [`Self::sample_lattice`] at unit world direction `dir`.
    fn pdf_lattice(&self, weights: &[f32], norm: f32, dir: Vec3) -> f32 {
        let weight = |x: usize, y: usize| weights[y * self.width + x % self.width];
        let uv = self.uv(dir);
        let sin_theta = (uv.y * PI).sin();
        if !(sin_theta > 0.0) {
            return 0.0;
        }
        let (i, j, a, b) = self.cell_of(uv);
        let top = weight(i, j) * (1.0 - a) + weight(i + 1, j) * a;
        let bottom = weight(i, j + 1) * (1.0 - a) + weight(i + 1, j + 1) * a;
        let density_uv = (top * (1.0 - b) + bottom * b) * norm;
        density_uv / (2.0 * PI * PI * sin_theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(w: u32, h: u32, f: impl Fn(u32, u32) -> Color) -> EnvMap {
        let pixels = (0..w * h).map(|i| f(i % w, i / w)).collect();
        EnvMap::new(&Film { width: w, height: h, pixels }, 1.0, Mat3::IDENTITY)
    }

    /// A constant map integrates to 4π L; its lookups are L everywhere.
    #[test]
    fn a_constant_map_is_a_constant_sky() {
        let m = map(8, 4, |_, _| Color::splat(2.0));
        assert!((m.total().x - 8.0 * PI).abs() < 1e-5 * 8.0 * PI, "{}", m.total());
        for d in [Vec3::X, Vec3::Y, -Vec3::Y, Vec3::new(0.3, -0.4, 0.866).normalize()] {
            assert!((m.eval(d) - Color::splat(2.0)).abs().max_element() < 1e-6);
        }
        // uv and direction are inverse; +y is v = 0 (the image's top).
        assert!(m.uv(Vec3::Y).y.abs() < 1e-6);
        let d = Vec3::new(0.6, 0.0, -0.8);
        assert!((m.direction(m.uv(d)) - d).length() < 1e-5);
    }

    /// The exact integral against a fine midpoint sum of the lookups times
    /// the solid angle, on an uneven map; where the map is black (its
    /// lower half here) no direction is drawn, and wherever light arrives
    /// the density is positive.
    #[test]
    fn the_integral_is_exact_and_the_density_covers_the_light() {
        let m = map(12, 7, |x, y| if y >= 4 { Color::ZERO } else { Color::new(1.0 + x as f32, 0.5 * y as f32, 3.0) });
        let (nu, nv) = (1200usize, 1400usize);
        let mut sum = glam::DVec3::ZERO;
        for j in 0..nv {
            let v = (j as f64 + 0.5) / nv as f64;
            let w = (std::f64::consts::PI * v).sin() * 2.0 * std::f64::consts::PI.powi(2) / (nu * nv) as f64;
            for i in 0..nu {
                let uv = Vec2::new(((i as f64 + 0.5) / nu as f64) as f32, v as f32);
                sum += m.lookup(uv).as_dvec3() * w;
            }
        }
        let exact = m.total().as_dvec3();
        assert!((sum - exact).abs().max_element() < 1e-4 * exact.max_element(), "{sum} vs {exact}");
        let mut state = 99u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 40) as f32) / (1u64 << 24) as f32
        };
        for _ in 0..20_000 {
            let (d, pdf) = m.sample(Vec2::new(next(), next()));
            assert!(pdf > 0.0 && m.eval(d).max_element() > 0.0, "{d}: pdf {pdf}, {}", m.eval(d));
            let d = crate::sampling::uniform_cone(Vec2::new(next(), next()), -1.0).normalize();
            assert_eq!(m.eval(d).max_element() > 0.0, m.pdf(d) > 0.0, "{d}");
        }
    }

    /// Irradiance from a constant map by its own sampling: E = π L on any
    /// plane, whichever way it faces, within four standard errors.
    #[test]
    fn sampled_irradiance_is_pi_l() {
        let m = map(16, 8, |_, _| Color::splat(2.0));
        let mut state = 5u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 40) as f32) / (1u64 << 24) as f32
        };
        for n in [Vec3::Z, -Vec3::Z, Vec3::Y, Vec3::new(0.5, -0.5, 0.7).normalize()] {
            let k = 1_000_000;
            let (mut sum, mut squares) = (0.0f64, 0.0f64);
            for _ in 0..k {
                let (d, pdf) = m.sample(Vec2::new(next(), next()));
                let e = (m.eval(d).x * d.dot(n).max(0.0) / pdf) as f64;
                sum += e;
                squares += e * e;
            }
            let mean = sum / k as f64;
            let se = ((squares / k as f64 - mean * mean) / k as f64).sqrt();
            assert!((mean - 2.0 * std::f64::consts::PI).abs() < 4.0 * se, "{n}: {mean} +- {se}");
        }
    }

    /// χ² test of the sampled directions against the pdf, on a map with a
    /// bright patch: 32 x 16 bins in (u, v), each bin's expected count from
    /// the pdf integrated over it.
    #[test]
    fn sampling_follows_its_pdf() {
        let m =
            map(
                16,
                8,
                |x, y| if (5..8).contains(&x) && (2..4).contains(&y) { Color::splat(50.0) } else { Color::splat(0.2) },
            );
        let (bu, bv) = (32usize, 16usize);
        let n = 400_000;
        let mut counts = vec![0f64; bu * bv];
        let mut mismatched = 0;
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 40) as f32) / (1u64 << 24) as f32
        };
        for _ in 0..n {
            let (d, pdf) = m.sample(Vec2::new(next(), next()));
            assert!(pdf > 0.0);
            // Only where rounding puts a direction on a pixel's border.
            mismatched += ((pdf - m.pdf(d)).abs() > 1e-3 * pdf) as u32;
            let uv = m.uv(d);
            let (i, j) = (((uv.x * bu as f32) as usize).min(bu - 1), ((uv.y * bv as f32) as usize).min(bv - 1));
            counts[j * bu + i] += 1.0;
        }
        assert!(mismatched < n / 1000, "{mismatched} pdfs differ from the sample's");
        let sub = 16;
        let (mut chi2, mut dof) = (0.0, 0);
        for j in 0..bv {
            for i in 0..bu {
                let mut e = 0.0f64;
                for b in 0..sub {
                    for a in 0..sub {
                        let uv = Vec2::new(
                            (i as f32 + (a as f32 + 0.5) / sub as f32) / bu as f32,
                            (j as f32 + (b as f32 + 0.5) / sub as f32) / bv as f32,
                        );
                        let dw = 2.0 * PI * PI * (uv.y * PI).sin() / (bu * bv * sub * sub) as f32;
                        e += (m.pdf(m.direction(uv)) * dw) as f64;
                    }
                }
                let e = e * n as f64;
                if e >= 5.0 {
                    chi2 += (counts[j * bu + i] - e).powi(2) / e;
                    dof += 1;
                }
            }
        }
        let k = dof as f64 - 1.0;
        let limit = k * (1.0 - 2.0 / (9.0 * k) + 3.719 * (2.0 / (9.0 * k)).sqrt()).powi(3);
        assert!(chi2 < limit, "χ² {chi2:.1} over {limit:.1} ({dof} bins)");
    }
}
