//! Radiance from an environment map at infinity (Mitsuba's `envmap`):
//! directions drawn from the map by luminance, photons from the scene's
//! box as each direction sees it (infinity.rs), caustic photons aimed at
//! the glass and mirrors along directions drawn from the map, so mostly
//! from its bright parts, with the exact density.

use super::infinity::Reach;
use super::{aimed_across, Aim, Aimed, Emitted, Incident, Source};
use crate::envmap::EnvMap;
use crate::math::{Color, Ray, Vertex};
use crate::sampling::{next_2d, Rng};
use glam::{Vec2, Vec3};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct Environment {
    pub map: Arc<EnvMap>,
    pub reach: Reach,
    /// ∫ L |ω_k| dω per world axis ([`EnvMap::abs_moments`]).
    moments: [Color; 3],
}

impl Environment {
    /// Unplaced: [`Source::place`] gives it the scene's box.
    pub fn new(map: Arc<EnvMap>) -> Self {
        let moments = map.abs_moments();
        Environment { map, reach: Reach::default(), moments }
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

    fn compensates(&self) -> bool {
        self.map.compensates()
    }

    /// From the map less its mean: the sun, not the sky, which the cosine
    /// strategy sharing the light finds better.
    fn sample_li_shared(&self, _p: Vertex, _n: Vec3, u: Vec2) -> Option<Incident> {
        let (dir, pdf) = self.map.sample_compensated(u);
        (pdf > 0.0).then(|| Incident { dir, target: None, intensity: self.map.eval(dir) / pdf, prim: None })
    }

    fn pdf_li_shared(&self, _p: Vertex, _n: Vec3, dir: Vec3) -> f32 {
        self.map.pdf_compensated(dir)
    }

    /// A direction drawn from the map, a start on the box's shadow across
    /// it: the photon carries L A / pdf, A the shadow's area, as its
    /// share of the power the map sends into the box, per channel.
    #[inline]
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Emitted {
        let (towards, pdf) = self.map.sample(u_dir);
        let dir = -towards;
        let Some(origin) = self.reach.start(dir, u_pos) else {
            return Emitted { ray: Ray::new(self.reach.upstream(dir), dir), departure: None, weight: Color::ZERO };
        };
        let flux = self.map.eval(towards) * (self.reach.area(dir) / pdf);
        let power = self.power();
        let share = |f: f32, p: f32| if p > 0.0 { f / p } else { 0.0 };
        let weight = Color::new(share(flux.x, power.x), share(flux.y, power.y), share(flux.z, power.z));
        let weight = if pdf > 0.0 && weight.is_finite() { weight } else { Color::ZERO };
        Emitted { ray: Ray::new(origin, dir), departure: None, weight }
    }

    fn pdf_le(&self, ray: &Ray) -> (f32, f32) {
        (self.reach.pdf(ray), self.map.pdf(-ray.dir))
    }

    /// A direction drawn from the map: a directional light of irradiance
    /// L / pdf along it.
    #[inline]
    fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed> {
        let u = [next_2d(rng), next_2d(rng)];
        self.sample_le_towards_at(aim, u, rng)
    }

    /// The direction from `u[0]`, the start on the aimed disk from `u[1]`.
    #[inline]
    fn sample_le_towards_at(&self, aim: &impl Aim, u: [Vec2; 2], _rng: &mut Rng) -> Option<Aimed> {
        let (towards, pdf) = self.map.sample(u[0]);
        if !(pdf > 0.0) {
            return None;
        }
        let direction = -towards;
        let plane = self.reach.upstream(direction);
        Some(aimed_across(direction, self.map.eval(towards) / pdf, plane, aim, u[1]))
    }

    /// What the map sends into the scene's box: Σ_k F_k ∫ L |ω_k| dω.
    fn power(&self) -> Color {
        self.reach.power(self.moments)
    }

    fn is_delta(&self) -> bool {
        false
    }

    fn radiance_from_infinity(&self, towards: Vec3) -> Color {
        self.map.eval(towards)
    }

    fn place(&mut self, lo: Vec3, hi: Vec3) {
        self.reach = Reach::new(lo, hi);
    }

    /// Light from infinity keeps its radiance where the scene moves.
    fn moved(&mut self, _origin: Vec3, _scale: f32) {}

    fn describe(&self) -> String {
        "the environment map".to_string()
    }
}
