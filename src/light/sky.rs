//! Light from everywhere: radiance arriving equally from every direction
//! at infinity (Mitsuba's `constant`). Photons start on a disk facing their
//! direction that covers the scene's bounding sphere (`center`, `radius`),
//! outside it.

use super::{
    aimed_across, directional_reach, disk_pdf, disk_point, Aim, Aimed, Emitted, Incident, MitsubaEmitter, MitsubaParam,
    Source,
};
use crate::math::{Color, Frame, Ray, Vertex};
use crate::sampling::{cosine_hemisphere, next_2d, uniform_cone, Rng};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct Constant {
    pub radiance: Color,
    pub center: Vertex,
    pub radius: f32,
}

impl Constant {
    /// Unplaced: [`Source::place`] gives it its disk.
    pub fn new(radiance: Color) -> Self {
        Constant { radiance, center: Vec3::ZERO, radius: 0.0 }
    }
}

impl Source for Constant {
    /// By the cosine about `n` (pdf cos / π), so that an unoccluded
    /// diffuse point's estimate has no variance.
    #[inline]
    fn sample_li(&self, _p: Vertex, n: Vec3, u: Vec2) -> Option<Incident> {
        let local = cosine_hemisphere(u);
        if !(local.z > 0.0) {
            return None;
        }
        let dir = Frame::from_normal(n).to_world(local).normalize();
        Some(Incident { dir, target: None, intensity: self.radiance * (PI / local.z), prim: None })
    }

    fn pdf_li(&self, _p: Vertex, n: Vec3, dir: Vec3) -> f32 {
        dir.dot(n).max(0.0) / PI
    }

    /// Travelling along a uniform direction, from a uniform point of the
    /// disk facing it beyond the bounding sphere.
    #[inline]
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Emitted {
        let dir = uniform_cone(u_dir, -1.0).normalize();
        let origin = disk_point(self.center - dir * (2.0 * self.radius), dir, self.radius, u_pos);
        Emitted { ray: Ray::new(origin, dir), departure: None, weight: Color::ONE }
    }

    fn pdf_le(&self, ray: &Ray) -> (f32, f32) {
        let plane = self.center - ray.dir * (2.0 * self.radius);
        (disk_pdf(plane, ray.dir, self.radius, ray.origin), 1.0 / (4.0 * PI))
    }

    /// A uniform direction (pdf 1 / 4π), then as a directional light of
    /// irradiance L 4π along it.
    #[inline]
    fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed> {
        let direction = uniform_cone(next_2d(rng), -1.0).normalize();
        let plane = self.center - direction * (2.0 * self.radius);
        Some(aimed_across(direction, self.radiance * (4.0 * PI), plane, aim, rng))
    }

    /// Through the disk πR², from every direction: L 4π πR².
    fn power(&self) -> Color {
        self.radiance * (4.0 * PI * PI * self.radius * self.radius)
    }

    fn is_delta(&self) -> bool {
        false
    }

    fn radiance_from_infinity(&self, _towards: Vec3) -> Color {
        self.radiance
    }

    fn place(&mut self, lo: Vec3, hi: Vec3) {
        (self.center, self.radius) = directional_reach(Vec3::ZERO, lo, hi);
    }

    /// Light from infinity keeps its radiance where the scene moves.
    fn moved(&mut self, _origin: Vec3, _scale: f32) {}

    fn describe(&self) -> String {
        "the constant sky".to_string()
    }

    fn mitsuba(&self) -> Result<MitsubaEmitter, String> {
        Ok(MitsubaEmitter { plugin: "constant", params: vec![("radiance", MitsubaParam::Rgb(self.radiance))] })
    }
}
