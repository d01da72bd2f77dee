//! A projector (Mitsuba's `projector`): a pinhole at `position` shining
//! along `axes[2]` through the frustum |x / z| <= tan_x, |y / z| <= tan_y
//! of its frame, with the radiant intensity Mitsuba 3 gives it
//! (src/emitters/projector.cpp): π E s / cos³θ, so that a plane at unit
//! distance facing it receives the same light wherever the frustum reaches
//! it.

use super::{aimed_from, Aim, Aimed, Emitted, Incident, LightBounds, Source};
use crate::math::{Color, Ray, Vertex};
use crate::sampling::Rng;
use crate::texture::{SurfacePoint, Texture};
use glam::{Vec2, Vec3};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct Projector {
    pub position: Vertex,
    /// The frame's x, y and z (the axis) in world space, unit.
    pub axes: [Vec3; 3],
    /// π times the irradiance times the scale.
    pub scaled: Color,
    pub tan_x: f32,
    pub tan_y: f32,
    /// An image projected (its irradiance times `scaled`), and its mean
    /// over the window; `None`: constant.
    pub pattern: Option<(Arc<Texture>, Color)>,
}

impl Projector {
    /// The direction from the projector to world direction `dir` in its
    /// frame, if inside the frustum.
    #[inline]
    fn local(&self, dir: Vec3) -> Option<Vec3> {
        let l = Vec3::new(dir.dot(self.axes[0]), dir.dot(self.axes[1]), dir.dot(self.axes[2]));
        (l.z > 0.0 && l.x.abs() <= self.tan_x * l.z && l.y.abs() <= self.tan_y * l.z).then_some(l)
    }

    /// Radiant intensity towards unit world direction `dir`.
    #[inline]
    pub fn intensity_towards(&self, dir: Vec3) -> Color {
        match self.local(dir) {
            Some(l) => self.scaled * self.pattern_at(l) / (l.z * l.z * l.z),
            None => Color::ZERO,
        }
    }

    /// The image's value towards local direction `l`: Mitsuba's projector
    /// maps the window onto [0, 1]^2 with u growing towards -x and v
    /// towards -y (its perspective_projection).
    #[inline]
    fn pattern_at(&self, l: Vec3) -> Color {
        match &self.pattern {
            None => Color::ONE,
            Some((t, _)) => {
                let uv = Vec2::new(0.5 - 0.5 * l.x / (l.z * self.tan_x), 0.5 - 0.5 * l.y / (l.z * self.tan_y));
                t.eval(&SurfacePoint { uv, prim: 0, bary: Vec2::ZERO })
            }
        }
    }

    /// The pattern's mean over the window (1 without one).
    pub fn mean(&self) -> Color {
        self.pattern.as_ref().map_or(Color::ONE, |p| p.1)
    }

    /// A pattern's mean over [0, 1]^2, on a grid finer than any image
    /// photonmap reads in one lookup per texel.
    pub fn window_mean(t: &Texture) -> Color {
        grid_mean(|uv| t.eval(&SurfacePoint { uv, prim: 0, bary: Vec2::ZERO }))
    }
}

/// The mean of `f` over the unit square by the midpoint rule on 512^2 cells.
fn grid_mean(f: impl Fn(Vec2) -> Color) -> Color {
    let n = 512;
    let mut sum = glam::DVec3::ZERO;
    for j in 0..n {
        for i in 0..n {
            sum += f(Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32)).as_dvec3();
        }
    }
    (sum / (n * n) as f64).as_vec3()
}

impl Source for Projector {
    #[inline]
    fn sample_li(&self, p: Vertex, _n: Vec3, _u: Vec2) -> Option<Incident> {
        let to = self.position - p;
        let dist2 = to.length_squared();
        if !(dist2 > 0.0) {
            return None;
        }
        let dir = to / dist2.sqrt();
        let intensity = self.intensity_towards(-dir) / dist2;
        (intensity.is_finite() && intensity.max_element() > 0.0).then_some(Incident {
            dir,
            target: Some(self.position),
            intensity,
            prim: None,
        })
    }

    /// Uniform on the frustum's window at z = 1: in proportion to the
    /// intensity, as dω = cos³θ dA.
    #[inline]
    fn sample_le(&self, _u_pos: Vec2, u_dir: Vec2) -> Emitted {
        let (x, y) = ((2.0 * u_dir.x - 1.0) * self.tan_x, (2.0 * u_dir.y - 1.0) * self.tan_y);
        let dir = (self.axes[0] * x + self.axes[1] * y + self.axes[2]).normalize();
        let weight = match &self.pattern {
            None => Color::ONE,
            Some(_) => self.pattern_at(Vec3::new(x, y, 1.0)) / self.mean().max(Color::splat(1e-30)),
        };
        Emitted { ray: Ray::new(self.position, dir), departure: None, weight }
    }

    /// 1 / (window area cos³θ).
    fn pdf_le(&self, ray: &Ray) -> (f32, f32) {
        let pdf = self.local(ray.dir).map_or(0.0, |l| 1.0 / (4.0 * self.tan_x * self.tan_y * l.z * l.z * l.z));
        (1.0, pdf)
    }

    #[inline]
    fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed> {
        aimed_from(self.position, None, aim, rng, |dir| Some(self.intensity_towards(dir.normalize())))
    }

    /// dω = cos³θ dA on the plane z = 1: the frustum's area there.
    fn power(&self) -> Color {
        self.scaled * self.mean() * (4.0 * self.tan_x * self.tan_y)
    }

    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        Some((self.position, self.position))
    }

    /// The cone through the frustum's corners.
    fn light_bounds(&self) -> Option<LightBounds> {
        let (p, phi) = (self.position, self.power().max_element());
        let cos_o = 1.0 / (1.0 + self.tan_x * self.tan_x + self.tan_y * self.tan_y).sqrt();
        Some(LightBounds { lo: p, hi: p, phi, w: self.axes[2], cos_o, cos_e: 1.0 })
    }

    fn moved(&mut self, origin: Vec3, scale: f32) {
        self.position = (self.position - origin) * scale;
        self.scaled *= scale * scale;
    }

    fn describe(&self) -> String {
        format!("the projector at {}", self.position)
    }
}
