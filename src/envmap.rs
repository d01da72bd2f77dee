//! An environment map: radiance arriving from infinitely far away, read
//! from a latitude-longitude image, as Mitsuba 3's `envmap` defines it
//! (src/emitters/envmap.cpp): in the map's own frame a direction d has
//! u = atan2(d.x, -d.z) / 2π and v = acos(d.y) / π, +y up; the image is
//! looked up bilinearly with texel centres at u = (x + ½) / W, periodic,
//! and, as Mitsuba aligns the rows with the poles, at v = y / (H - 1);
//! `scale` multiplies it.
//!
//! Directions are drawn from the map's pixels in proportion to their
//! luminance times sin θ (the solid angle a pixel spans), mixed with a
//! share of uniform directions so that the density is positive wherever
//! bilinear interpolation carries light past a bright pixel's edge: the
//! pdf is exact for the mixture, never approximate.

use crate::film::Film;
use crate::math::Color;
use crate::sampling::{uniform_cone, Discrete};
use glam::{Mat3, Vec2, Vec3};
use std::f32::consts::PI;

/// The share of directions drawn uniformly over the sphere.
const UNIFORM: f32 = 0.15;

#[derive(Debug)]
pub struct EnvMap {
    width: usize,
    height: usize,
    texels: Vec<Color>,
    /// The map's frame in world space (a rotation) and back.
    to_world: Mat3,
    to_local: Mat3,
    pixels: Option<Discrete>,
    /// ∫ L dω over the sphere, per channel.
    total: Color,
}

impl EnvMap {
    /// `image` scaled by `scale`, its frame `to_world` (orthonormal).
    pub fn new(image: &Film, scale: f32, to_world: Mat3) -> Self {
        let (width, height) = (image.width as usize, image.height as usize);
        let texels: Vec<Color> = image.pixels.iter().map(|c| (*c * scale).max(Color::ZERO)).collect();
        let sin = |y: usize| (PI * (y as f32 + 0.5) / height as f32).sin();
        let lum = |c: Color| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        let pixels = Discrete::new((0..width * height).map(|i| (lum(texels[i]) * sin(i / width)) as f64));
        let mut map =
            EnvMap { width, height, texels, to_world, to_local: to_world.transpose(), pixels, total: Color::ZERO };
        // ∫ L dω on a grid 4x finer than the image: each cell's value at
        // its centre times its solid angle, exact in θ (cos θ0 - cos θ1).
        let (nu, nv) = (4 * width, 4 * height);
        let mut total = glam::DVec3::ZERO;
        for j in 0..nv {
            let v = (j as f32 + 0.5) / nv as f32;
            let theta = |k: usize| std::f64::consts::PI * k as f64 / nv as f64;
            let w = theta(j).cos() - theta(j + 1).cos();
            for i in 0..nu {
                let u = (i as f32 + 0.5) / nu as f32;
                total += map.lookup(Vec2::new(u, v)).as_dvec3() * w;
            }
        }
        map.total = (total * (2.0 * std::f64::consts::PI / nu as f64)).as_vec3();
        map
    }

    /// ∫ L dω over the sphere, per channel.
    pub fn total(&self) -> Color {
        self.total
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

    /// A unit world direction towards the map and its density (solid
    /// angle), for a point `u` uniform in the unit square.
    pub fn sample(&self, u: Vec2) -> (Vec3, f32) {
        let dir = match &self.pixels {
            Some(pixels) if u.x >= UNIFORM => {
                let (i, rest) = pixels.sample((u.x - UNIFORM) / (1.0 - UNIFORM));
                let (px, py) = (i % self.width, i / self.width);
                let uv = Vec2::new((px as f32 + rest) / self.width as f32, (py as f32 + u.y) / self.height as f32);
                self.direction(uv)
            }
            Some(_) => uniform_cone(Vec2::new(u.x / UNIFORM, u.y), -1.0).normalize(),
            None => uniform_cone(u, -1.0).normalize(),
        };
        (dir, self.pdf(dir))
    }

    /// The density of [`Self::sample`] at unit world direction `dir`.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let uniform = 1.0 / (4.0 * PI);
        let Some(pixels) = &self.pixels else { return uniform };
        let uv = self.uv(dir);
        let px = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let py = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        let sin_theta = (uv.y * PI).sin();
        let map = if sin_theta > 0.0 {
            pixels.prob(py * self.width + px) * (self.width * self.height) as f32 / (2.0 * PI * PI * sin_theta)
        } else {
            0.0
        };
        UNIFORM * uniform + (1.0 - UNIFORM) * map
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

    /// Irradiance from a constant map by its own sampling: E = π L on any
    /// plane, whichever way it faces.
    #[test]
    fn sampled_irradiance_is_pi_l() {
        let m = map(16, 8, |_, _| Color::splat(2.0));
        for n in [Vec3::Z, -Vec3::Z, Vec3::Y, Vec3::new(0.5, -0.5, 0.7).normalize()] {
            let k = 400;
            let mut e = 0.0f64;
            for i in 0..k {
                for j in 0..k {
                    let u = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                    let (d, pdf) = m.sample(u);
                    e += (m.eval(d).x * d.dot(n).max(0.0) / pdf) as f64;
                }
            }
            e /= (k * k) as f64;
            assert!((e - 2.0 * std::f64::consts::PI).abs() < 2e-3 * e, "{n}: {e}");
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
