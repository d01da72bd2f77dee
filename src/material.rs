//! Surface materials: a closed set, spelled out.
//!
//! [`Phong`] is the Whitted course's material. The `trace` program shades it
//! with the course's formula; photonmap reads it as a physically plausible
//! BRDF (notes/scene-format.md): a Lambertian lobe m_l C / pi, a normalised
//! Phong lobe m_s S (m_sp + 2) / (2 pi) cos^m_sp(alpha) around the mirror
//! direction, and a perfect mirror m_r C. It conserves energy when
//! m_l C + m_s S + m_r C <= 1 per channel, which photonmap requires.

use crate::math::{max_component, Color, Frame};
use crate::optics::reflect;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// The course's Phong material (CS475 A3): colour C and the coefficients
/// m_a, m_l, m_s, m_sm, m_sp, m_r.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    pub color: Color,
    /// m_a: share of the ambient light A.
    pub ambient: f32,
    /// m_l: Lambertian reflectance.
    pub diffuse: f32,
    /// m_s: specular highlight strength.
    pub specular: f32,
    /// m_sm: metalness, the highlight's colour from white (0) to C (1).
    pub metalness: f32,
    /// m_sp: Phong exponent.
    pub shininess: f32,
    /// m_r: mirror reflection of the bounce ray.
    pub mirror: f32,
}

impl Phong {
    /// The highlight colour S = m_sm C + (1 - m_sm)(1, 1, 1).
    pub fn highlight(&self) -> Color {
        self.metalness * self.color + (1.0 - self.metalness) * Color::ONE
    }

    pub fn diffuse_rho(&self) -> Color {
        self.diffuse * self.color
    }

    pub fn specular_rho(&self) -> Color {
        self.specular * self.highlight()
    }

    pub fn mirror_rho(&self) -> Color {
        self.mirror * self.color
    }

    /// The largest fraction of light any channel reflects (over 1: the
    /// material creates energy).
    pub fn albedo_bound(&self) -> f32 {
        max_component(self.diffuse_rho() + self.specular_rho() + self.mirror_rho())
    }

    /// The course's specular factor max(r . v, 0)^m_sp, r the mirror image
    /// of `to_light` about `n`, all unit vectors.
    pub fn highlight_factor(&self, n: Vec3, to_light: Vec3, to_viewer: Vec3) -> f32 {
        let r = 2.0 * to_light.dot(n) * n - to_light;
        let c = r.dot(to_viewer);
        if c > 0.0 {
            c.powf(self.shininess)
        } else {
            0.0
        }
    }

    /// Physically based BRDF without the mirror lobe, for unit `n` (the side
    /// of the viewer), `to_light` and `to_viewer`.
    pub fn brdf(&self, n: Vec3, to_light: Vec3, to_viewer: Vec3) -> Color {
        let glossy = if self.specular > 0.0 {
            self.specular_rho() * ((self.shininess + 2.0) / (2.0 * PI) * self.highlight_factor(n, to_light, to_viewer))
        } else {
            Color::ZERO
        };
        self.diffuse_rho() / PI + glossy
    }

    /// A direction from the normalised Phong lobe around the mirror image of
    /// `to_viewer` (pdf (m_sp + 1) / (2 pi) cos^m_sp alpha), and the weight
    /// f cos / pdf = m_s S (m_sp + 2) / (m_sp + 1) cos theta. `None` below the
    /// surface.
    pub fn sample_glossy(&self, n: Vec3, to_viewer: Vec3, u: Vec2) -> Option<(Vec3, Color)> {
        let frame = Frame::from_normal(n);
        let r = frame.to_world(reflect(frame.to_local(to_viewer))).normalize();
        let cos_a = u.x.powf(1.0 / (self.shininess + 1.0));
        let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let lobe = Frame::from_normal(r);
        let dir = lobe.to_world(Vec3::new(sin_a * phi.cos(), sin_a * phi.sin(), cos_a)).normalize();
        let cos_t = dir.dot(n);
        (cos_t > 0.0).then(|| (dir, self.specular_rho() * ((self.shininess + 2.0) / (self.shininess + 1.0) * cos_t)))
    }
}

/// One of the Phong material's lobes, as chosen for a bounce.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobe {
    Diffuse,
    Glossy,
    Mirror,
}

impl Phong {
    /// Russian roulette over the lobes: each is chosen with probability
    /// the largest channel of its albedo (scaled down if they add up to more
    /// than one), the rest is absorption. Returns the lobe and its probability.
    pub fn choose_lobe(&self, u: f32) -> Option<(Lobe, f32)> {
        let p = [
            max_component(self.diffuse_rho()),
            if self.specular > 0.0 { max_component(self.specular_rho()) } else { 0.0 },
            max_component(self.mirror_rho()),
        ];
        let total: f32 = p.iter().sum();
        let scale = if total > 1.0 { 1.0 / total } else { 1.0 };
        let mut acc = 0.0;
        for (lobe, p) in [Lobe::Diffuse, Lobe::Glossy, Lobe::Mirror].into_iter().zip(p) {
            let p = p * scale;
            acc += p;
            if p > 0.0 && u < acc {
                return Some((lobe, p));
            }
        }
        None
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Ideal diffuse reflector, BRDF = rho / pi, per channel.
    Lambertian { rho: Color },
    /// Perfect specular mirror.
    Mirror { reflectance: Color },
    /// Smooth dielectric: exact Fresnel, Snell refraction, total internal
    /// reflection. `ior` is the index inside (the side the normal points
    /// away from); light travelling inside loses exp(-absorption * distance)
    /// per channel (Beer–Lambert).
    Glass { ior: f32, absorption: Color },
    /// The Whitted course's material (see [`Phong`]).
    Phong(Phong),
    /// A light's own surface: it emits (through its light) and reflects nothing.
    Emitter,
}

impl Material {
    /// Clear glass of index `ior`.
    pub fn glass(ior: f32) -> Self {
        Material::Glass { ior, absorption: Color::ZERO }
    }

    /// Mirror and glass: light leaving them is found by following rays, never
    /// by density estimation.
    pub fn is_specular(&self) -> bool {
        matches!(self, Material::Mirror { .. } | Material::Glass { .. })
    }

    /// Whether light can leave the surface by a perfect mirror or refraction
    /// (photons aimed at it may make caustics).
    pub fn has_specular_lobe(&self) -> bool {
        match self {
            Material::Phong(p) => max_component(p.mirror_rho()) > 0.0,
            m => m.is_specular(),
        }
    }

    /// A surface that stores photons and is shaded by the estimators: its
    /// Lambertian reflectance; black diffuse surfaces reflect nothing and
    /// need no estimate.
    pub fn diffuse_rho(&self) -> Option<Color> {
        let rho = match self {
            Material::Lambertian { rho } => *rho,
            Material::Phong(p) => p.diffuse_rho(),
            _ => return None,
        };
        (max_component(rho) > 0.0).then_some(rho)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, Domain};

    fn shiny(shininess: f32) -> Phong {
        Phong {
            color: Color::new(0.9, 0.5, 0.2),
            ambient: 0.1,
            diffuse: 0.3,
            specular: 0.5,
            metalness: 0.5,
            shininess,
            mirror: 0.1,
        }
    }

    /// The glossy lobe's sampling weight f cos / pdf agrees with the BRDF
    /// divided by the pdf, and the lobe's albedo at normal incidence stays
    /// below m_s S (energy conserving), by Monte Carlo over the hemisphere.
    #[test]
    fn glossy_lobe_is_normalised_and_its_sampler_matches_its_brdf() {
        let n = Vec3::Z;
        let wo = Vec3::Z;
        for shininess in [1.0f32, 10.0, 100.0] {
            let p = Phong { diffuse: 0.0, ..shiny(shininess) };
            let mut rng = stream(1, Domain::Camera, shininess as u64);
            let count = 200_000;
            let mut sampled = 0.0f64;
            let mut uniform = 0.0f64;
            for _ in 0..count {
                if let Some((_, w)) = p.sample_glossy(n, wo, next_2d(&mut rng)) {
                    sampled += w.x as f64;
                }
                // Uniform hemisphere estimate of the same integral.
                let d = crate::sampling::uniform_cone(next_2d(&mut rng), 0.0);
                uniform += (p.brdf(n, d, wo).x * d.z * 2.0 * PI) as f64;
            }
            let (a, b) = (sampled / count as f64, uniform / count as f64);
            let bound = p.specular_rho().x as f64;
            assert!((a - b).abs() < 0.02 * bound + 0.02 * b, "m_sp {shininess}: {a} vs {b}");
            assert!(a <= bound * 1.001, "albedo {a} over {bound}");
            assert!(a > 0.5 * bound);
        }
    }

    #[test]
    fn highlight_colour_interpolates_with_metalness() {
        let mut p = shiny(10.0);
        p.metalness = 0.0;
        assert_eq!(p.highlight(), Color::ONE);
        p.metalness = 1.0;
        assert_eq!(p.highlight(), p.color);
        // Peak of the highlight: viewer on the mirror direction.
        let l = Vec3::new(1.0, 0.0, 1.0).normalize();
        let v = Vec3::new(-1.0, 0.0, 1.0).normalize();
        assert!((p.highlight_factor(Vec3::Z, l, v) - 1.0).abs() < 1e-6);
        assert_eq!(p.highlight_factor(Vec3::Z, l, l), 0.0f32.max((2.0 * 0.5f32 - 1.0).powf(10.0)));
    }
}
