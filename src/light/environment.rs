//! Radiance from an environment map at infinity (Mitsuba's `envmap`):
//! directions drawn from the map by luminance, photons from a disk across
//! them as for the constant sky.

use super::{aimed_across, directional_reach, disk_pdf, disk_point, Aim, Aimed, Emitted, Incident, Source};
use crate::envmap::EnvMap;
use crate::math::{Color, Ray, Vertex};
use crate::sampling::{next_2d, Rng};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct Environment {
    pub map: Arc<EnvMap>,
    pub center: Vertex,
    pub radius: f32,
}

impl Environment {
    /// Unplaced: [`Source::place`] gives it its disk.
    pub fn new(map: Arc<EnvMap>) -> Self {
        Environment { map, center: Vec3::ZERO, radius: 0.0 }
    }
}

impl Source for Environment {
    #[inline]
    fn sample_li(&self, _p: Vertex, _n: Vec3, u: Vec2) -> Option<Incident> {
        let (dir, pdf) = self.map.sample(u);
        (pdf > 0.0).then(|| Incident { dir, target: None, intensity: self.map.eval(dir) / pdf, prim: None })
    }

    fn pdf_li(&self, _p: Vertex, _n: Vec3, dir: Vec3) -> f32 {
        self.map.pdf(dir)
    }

    /// A direction drawn from the map; its photon carries L / (pdf ∫ L dω)
    /// of the mean share, per channel.
    #[inline]
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Emitted {
        let (towards, pdf) = self.map.sample(u_dir);
        let dir = -towards;
        let total = self.map.total();
        let l = self.map.eval(towards);
        let weight = Color::new(
            if total.x > 0.0 { l.x / (pdf * total.x) } else { 0.0 },
            if total.y > 0.0 { l.y / (pdf * total.y) } else { 0.0 },
            if total.z > 0.0 { l.z / (pdf * total.z) } else { 0.0 },
        );
        let origin = disk_point(self.center - dir * (2.0 * self.radius), dir, self.radius, u_pos);
        let weight = if pdf > 0.0 && weight.is_finite() { weight } else { Color::ZERO };
        Emitted { ray: Ray::new(origin, dir), departure: None, weight }
    }

    fn pdf_le(&self, ray: &Ray) -> (f32, f32) {
        let plane = self.center - ray.dir * (2.0 * self.radius);
        (disk_pdf(plane, ray.dir, self.radius, ray.origin), self.map.pdf(-ray.dir))
    }

    /// A direction drawn from the map: a directional light of irradiance
    /// L / pdf along it.
    #[inline]
    fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed> {
        let (towards, pdf) = self.map.sample(next_2d(rng));
        if !(pdf > 0.0) {
            return None;
        }
        let direction = -towards;
        let plane = self.center - direction * (2.0 * self.radius);
        Some(aimed_across(direction, self.map.eval(towards) / pdf, plane, aim, rng))
    }

    fn power(&self) -> Color {
        self.map.total() * (PI * self.radius * self.radius)
    }

    fn is_delta(&self) -> bool {
        false
    }

    fn radiance_from_infinity(&self, towards: Vec3) -> Color {
        self.map.eval(towards)
    }

    fn place(&mut self, lo: Vec3, hi: Vec3) {
        (self.center, self.radius) = directional_reach(Vec3::ZERO, lo, hi);
    }

    /// Light from infinity keeps its radiance where the scene moves.
    fn moved(&mut self, _origin: Vec3, _scale: f32) {}

    fn describe(&self) -> String {
        "the environment map".to_string()
    }
}
