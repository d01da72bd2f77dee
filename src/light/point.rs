//! A point light: `intensity` (W/sr) equally in every direction; the
//! Whitted course dims it as 1 / (d + dead_distance)^falloff (physical: 2, 0).

use super::{aimed_from, Aim, Aimed, Emitted, Incident, LightBounds, MitsubaEmitter, MitsubaParam, Source};
use crate::math::{Color, Ray, Vertex};
use crate::sampling::{uniform_cone, Rng};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vertex,
    pub intensity: Color,
    pub falloff: f32,
    pub dead_distance: f32,
}

impl Source for PointLight {
    #[inline]
    fn sample_li(&self, p: Vertex, _n: Vec3, _u: Vec2) -> Option<Incident> {
        let to = self.position - p;
        let dist = to.length();
        if !(dist > 0.0) {
            return None;
        }
        let scale = (dist + self.dead_distance).powf(-self.falloff);
        let intensity = self.intensity * scale;
        intensity.is_finite().then_some(Incident { dir: to / dist, target: Some(self.position), intensity, prim: None })
    }

    /// A uniform direction.
    #[inline]
    fn sample_le(&self, _u_pos: Vec2, u_dir: Vec2) -> Emitted {
        Emitted {
            ray: Ray::new(self.position, uniform_cone(u_dir, -1.0).normalize()),
            departure: None,
            weight: Color::ONE,
        }
    }

    fn pdf_le(&self, _ray: &Ray) -> (f32, f32) {
        (1.0, 1.0 / (4.0 * PI))
    }

    #[inline]
    fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed> {
        aimed_from(self.position, None, aim, rng, |_| Some(self.intensity))
    }

    fn power(&self) -> Color {
        4.0 * PI * self.intensity
    }

    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        Some((self.position, self.position))
    }

    /// Every direction.
    fn light_bounds(&self) -> Option<LightBounds> {
        let (p, phi) = (self.position, self.power().max_element());
        Some(LightBounds { lo: p, hi: p, phi, w: Vec3::Z, cos_o: -1.0, cos_e: 0.0 })
    }

    fn moved(&mut self, origin: Vec3, scale: f32) {
        self.position = (self.position - origin) * scale;
        self.intensity *= scale * scale;
    }

    fn describe(&self) -> String {
        format!("the point light at {}", self.position)
    }

    fn mitsuba(&self) -> Result<MitsubaEmitter, String> {
        let (falloff, dead_distance) = (self.falloff, self.dead_distance);
        if falloff != 2.0 || dead_distance != 0.0 {
            return Err(format!(
                "a point light dimmed as 1/(d + {dead_distance})^{falloff} has no equivalent in Mitsuba 3 (its \
                 point lights dim as 1/d^2)"
            ));
        }
        Ok(MitsubaEmitter {
            plugin: "point",
            params: vec![
                ("position", MitsubaParam::Point(self.position)),
                ("intensity", MitsubaParam::Rgb(self.intensity)),
            ],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_light_dims_with_the_course_falloff() {
        let l = PointLight { position: Vec3::ZERO, intensity: Color::splat(8.0), falloff: 1.0, dead_distance: 2.0 };
        let inc = l.sample_li(Vec3::new(0.0, 6.0, 0.0), Vec3::Y, Vec2::ZERO).unwrap();
        assert!((inc.intensity.x - 1.0).abs() < 1e-6);
        assert!((inc.dir + Vec3::Y).length() < 1e-6);
    }
}
