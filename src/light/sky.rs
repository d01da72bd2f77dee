//! Light from everywhere: radiance arriving equally from every direction
//! at infinity (Mitsuba's `constant`). Photons travel along uniform
//! directions from the scene's box as each direction sees it
//! (infinity.rs).

use super::infinity::Reach;
use super::{aimed_across, Aim, Aimed, Emitted, Incident, MitsubaEmitter, MitsubaParam, Source};
use crate::math::{Color, Frame, Ray, Vertex};
use crate::sampling::{cosine_hemisphere, next_2d, uniform_cone, Rng};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct Constant {
    pub radiance: Color,
    pub reach: Reach,
}

impl Constant {
    /// Unplaced: [`Source::place`] gives it the scene's box.
    pub fn new(radiance: Color) -> Self {
        Constant { radiance, reach: Reach::default() }
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

    /// Travelling along a uniform direction, from a point uniform on the
    /// box's shadow across it: L 4π A of the power per photon.
    #[inline]
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Emitted {
        let dir = uniform_cone(u_dir, -1.0).normalize();
        let Some(origin) = self.reach.start(dir, u_pos) else {
            return Emitted { ray: Ray::new(self.reach.upstream(dir), dir), departure: None, weight: Color::ZERO };
        };
        // L 4π A over the power L 2π Σ F_k.
        let faces = self.reach.faces();
        let weight = 2.0 * self.reach.area(dir) / (faces.x + faces.y + faces.z);
        Emitted { ray: Ray::new(origin, dir), departure: None, weight: Color::splat(weight) }
    }

    fn pdf_le(&self, ray: &Ray) -> (f32, f32) {
        (self.reach.pdf(ray), 1.0 / (4.0 * PI))
    }

    /// A uniform direction (pdf 1 / 4π), then as a directional light of
    /// irradiance L 4π along it.
    #[inline]
    fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed> {
        let u = [next_2d(rng), next_2d(rng)];
        self.sample_le_towards_at(aim, u, rng)
    }

    /// The direction from `u[0]`, the start on the aimed disk from `u[1]`.
    #[inline]
    fn sample_le_towards_at(&self, aim: &impl Aim, u: [Vec2; 2], _rng: &mut Rng) -> Option<Aimed> {
        let direction = uniform_cone(u[0], -1.0).normalize();
        let plane = self.reach.upstream(direction);
        Some(aimed_across(direction, self.radiance * (4.0 * PI), plane, aim, u[1]))
    }

    /// Into the scene's box from every direction: ∫ L A(ω) dω = L 2π Σ F_k
    /// (π L times the box's surface).
    fn power(&self) -> Color {
        let faces = self.reach.faces();
        self.radiance * (2.0 * PI * (faces.x + faces.y + faces.z))
    }

    fn is_delta(&self) -> bool {
        false
    }

    fn radiance_from_infinity(&self, _towards: Vec3) -> Color {
        self.radiance
    }

    fn place(&mut self, lo: Vec3, hi: Vec3) {
        self.reach = Reach::new(lo, hi);
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
