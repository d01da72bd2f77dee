//! A directional light: parallel light travelling along unit `direction`,
//! of `irradiance` on a surface facing it. Photons start on a disk facing
//! the light that covers the scene (`reach`: its centre and radius).

use super::{
    aimed_across, directional_reach, disk_pdf, disk_point, Aim, Aimed, Emitted, Incident, MitsubaEmitter, MitsubaParam,
    Source,
};
use crate::math::{Color, Ray, Vertex};
use crate::sampling::{next_2d, Rng};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct Directional {
    pub direction: Vec3,
    pub irradiance: Color,
    pub reach: (Vertex, f32),
}

impl Directional {
    /// Unplaced: [`Source::place`] gives it its reach.
    pub fn new(direction: Vec3, irradiance: Color) -> Self {
        Directional { direction, irradiance, reach: (Vec3::ZERO, 0.0) }
    }
}

impl Source for Directional {
    #[inline]
    fn sample_li(&self, _p: Vertex, _n: Vec3, _u: Vec2) -> Option<Incident> {
        Some(Incident { dir: -self.direction, target: None, intensity: self.irradiance, prim: None })
    }

    /// A uniform point of the disk across the light.
    #[inline]
    fn sample_le(&self, u_pos: Vec2, _u_dir: Vec2) -> Emitted {
        let origin = disk_point(self.reach.0, self.direction, self.reach.1, u_pos);
        Emitted { ray: Ray::new(origin, self.direction), departure: None, weight: Color::ONE }
    }

    fn pdf_le(&self, ray: &Ray) -> (f32, f32) {
        (disk_pdf(self.reach.0, self.direction, self.reach.1, ray.origin), 1.0)
    }

    #[inline]
    fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed> {
        Some(aimed_across(self.direction, self.irradiance, self.reach.0, aim, next_2d(rng)))
    }

    fn power(&self) -> Color {
        PI * self.reach.1 * self.reach.1 * self.irradiance
    }

    fn place(&mut self, lo: Vec3, hi: Vec3) {
        self.reach = directional_reach(self.direction, lo, hi);
    }

    /// Light from infinity keeps its radiance where the scene moves.
    fn moved(&mut self, _origin: Vec3, _scale: f32) {}

    fn describe(&self) -> String {
        format!("the directional light along {}", self.direction)
    }

    fn mitsuba(&self) -> Result<MitsubaEmitter, String> {
        Ok(MitsubaEmitter {
            plugin: "directional",
            params: vec![
                ("direction", MitsubaParam::Vector(self.direction)),
                ("irradiance", MitsubaParam::Rgb(self.irradiance)),
            ],
        })
    }
}
