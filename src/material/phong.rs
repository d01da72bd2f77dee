//! The Whitted course's Phong material (CS475 A3). The `trace` program
//! shades it with the course's formula; photonmap reads it as a physically
//! plausible BRDF (notes/scene-format.md): a Lambertian lobe m_l C / pi, a
//! normalised Phong lobe m_s S (m_sp + 2) / (2 pi) cos^m_sp(alpha) around
//! the mirror direction, and a perfect mirror m_r C. It conserves energy
//! when m_l C + m_s S + m_r C <= 1 per channel, which photonmap requires.
//!
//! Directions are in the local frame of the surface (normal +z, both
//! `wo` and `wi` on its side).

use crate::math::{max_component, Color, Frame};
use crate::optics::reflect;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// The course's Phong material: colour C and the coefficients m_a, m_l,
/// m_s, m_sm, m_sp, m_r.
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

    /// Whether the glossy lobe reflects anything.
    pub fn is_glossy(&self) -> bool {
        self.specular > 0.0
    }

    /// The largest fraction of light any channel reflects (over 1: the
    /// material creates energy).
    pub fn albedo_bound(&self) -> f32 {
        max_component(self.diffuse_rho() + self.specular_rho() + self.mirror_rho())
    }

    /// The chance of each lobe (diffuse, glossy, mirror) when one is chosen
    /// for a scattered direction: the largest channel of its albedo.
    pub fn lobe_weights(&self) -> [f32; 3] {
        [
            max_component(self.diffuse_rho()),
            if self.is_glossy() { max_component(self.specular_rho()) } else { 0.0 },
            max_component(self.mirror_rho()),
        ]
    }

    /// The course's specular factor max(r . v, 0)^m_sp, r the mirror image
    /// of `to_light` about `n`, all unit vectors (any frame).
    pub fn highlight_factor(&self, n: Vec3, to_light: Vec3, to_viewer: Vec3) -> f32 {
        let r = 2.0 * to_light.dot(n) * n - to_light;
        let c = r.dot(to_viewer);
        if c > 0.0 {
            c.powf(self.shininess)
        } else {
            0.0
        }
    }

    /// The glossy lobe's BRDF for local `wo` and `wi`.
    pub fn glossy(&self, wo: Vec3, wi: Vec3) -> Color {
        if !self.is_glossy() {
            return Color::ZERO;
        }
        self.specular_rho() * ((self.shininess + 2.0) / (2.0 * PI) * self.highlight_factor(Vec3::Z, wi, wo))
    }

    /// The glossy lobe's sampling density: (m_sp + 1) / (2 pi) cos^m_sp
    /// of the angle between `wi` and the mirror image of `wo`.
    pub fn glossy_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let c = reflect(wo).dot(wi);
        if !self.is_glossy() || !(c > 0.0) || !(wi.z > 0.0) {
            return 0.0;
        }
        (self.shininess + 1.0) / (2.0 * PI) * c.powf(self.shininess)
    }

    /// A direction from the normalised Phong lobe around the mirror image of
    /// `wo` (pdf [`Self::glossy_pdf`]), and the weight f cos / pdf = m_s S
    /// (m_sp + 2) / (m_sp + 1) cos theta. `None` below the surface.
    pub fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Option<(Vec3, Color)> {
        let r = reflect(wo);
        let cos_a = u.x.powf(1.0 / (self.shininess + 1.0));
        let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let wi = Frame::from_normal(r).to_world(Vec3::new(sin_a * phi.cos(), sin_a * phi.sin(), cos_a)).normalize();
        (wi.z > 0.0).then(|| (wi, self.specular_rho() * ((self.shininess + 2.0) / (self.shininess + 1.0) * wi.z)))
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
        let wo = Vec3::Z;
        for shininess in [1.0f32, 10.0, 100.0] {
            let p = Phong { diffuse: 0.0, ..shiny(shininess) };
            let mut rng = stream(1, Domain::Camera, shininess as u64);
            let count = 200_000;
            let mut sampled = 0.0f64;
            let mut uniform = 0.0f64;
            for _ in 0..count {
                if let Some((wi, w)) = p.sample_glossy(wo, next_2d(&mut rng)) {
                    sampled += w.x as f64;
                    // The weight is f cos / pdf.
                    let want = p.glossy(wo, wi).x * wi.z / p.glossy_pdf(wo, wi);
                    assert!((w.x - want).abs() <= 1e-3 * want.max(1e-3), "{} vs {want}", w.x);
                }
                // Uniform hemisphere estimate of the same integral.
                let d = crate::sampling::uniform_cone(next_2d(&mut rng), 0.0);
                uniform += (p.glossy(wo, d).x * d.z * 2.0 * PI) as f64;
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
