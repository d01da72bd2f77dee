//! A spot light (Mitsuba's `spot`): a point emitting `intensity` (W/sr)
//! into a cone, optionally through an image.

use super::{aimed_from, Aim, Aimed, Emitted, Incident, LightBounds, MitsubaEmitter, MitsubaParam, Source};
use crate::math::{Color, Frame, Ray, Vertex};
use crate::sampling::{uniform_cone, uniform_cone_pdf, Rng};
use crate::texture::{SurfacePoint, Texture};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

/// A spot's image towards local direction `l`: Mitsuba's spot maps the
/// cone onto uv as 0.5 + 0.5 (x, y) / (z tan cutoff) (spot.cpp).
fn spot_texel(t: &Texture, l: Vec3, cutoff: f32) -> Color {
    let k = 0.5 / (l.z * cutoff.tan());
    t.eval(&SurfacePoint { uv: Vec2::new(0.5 + l.x * k, 0.5 + l.y * k), prim: 0, bary: Vec2::ZERO })
}
/// A spot light: intensity I along its axis out to `beam` (the half-angle
/// of full intensity), then falling linearly in angle to zero at `cutoff`,
/// as Mitsuba 3's `spot` emitter defines it (src/emitters/spot.cpp).
#[derive(Clone, Debug)]
pub struct Spot {
    pub position: Vertex,
    /// z is the spot's axis.
    pub frame: Frame,
    pub intensity: Color,
    cos_cutoff: f32,
    cos_beam: f32,
    cutoff: f32,
    /// The angles as given, in degrees.
    cutoff_deg: f32,
    beam_deg: f32,
    inv_transition: f32,
    /// ∫ falloff dω over the sphere: power is I times it.
    solid_angle: f32,
    /// An image the spot projects (Mitsuba's `texture`), and ∫ falloff
    /// times it dω: power is I times that.
    pattern: Option<(Arc<Texture>, Color)>,
}

impl Spot {
    /// A spot at `position` along unit `axis`; angles in degrees, `beam`
    /// at most `cutoff`.
    pub fn new(position: Vertex, frame: Frame, intensity: Color, cutoff_deg: f32, beam_deg: f32) -> Self {
        let cutoff = cutoff_deg.to_radians();
        let beam = beam_deg.min(cutoff_deg).to_radians();
        let mut s = Spot {
            position,
            frame,
            intensity,
            cos_cutoff: cutoff.cos(),
            cos_beam: beam.cos(),
            cutoff,
            cutoff_deg,
            beam_deg: beam_deg.min(cutoff_deg),
            inv_transition: 1.0 / (cutoff - beam),
            solid_angle: 0.0,
            pattern: None,
        };
        // 2π ∫ falloff(θ) sin θ dθ over [0, cutoff], by the midpoint rule
        // on a fine grid (the falloff is piecewise smooth).
        let n = 4096;
        let h = cutoff as f64 / n as f64;
        let sum: f64 = (0..n)
            .map(|i| {
                let t = (i as f64 + 0.5) * h;
                s.falloff(t.cos() as f32) as f64 * t.sin()
            })
            .sum();
        s.solid_angle = (2.0 * std::f64::consts::PI * sum * h) as f32;
        s
    }

    /// The spot projecting `texture` through its cone, in `frame` (x and y
    /// as the spot's to_world places them).
    pub fn with_pattern(mut self, texture: Arc<Texture>) -> Self {
        // ∫ falloff T dω over the cone: the midpoint rule in (θ, φ).
        let (nt, np) = (512, 512);
        let mut sum = glam::DVec3::ZERO;
        for i in 0..nt {
            let theta = (i as f64 + 0.5) / nt as f64 * self.cutoff as f64;
            let w = theta.sin() * (self.cutoff as f64 / nt as f64) * (2.0 * std::f64::consts::PI / np as f64);
            let falloff = self.falloff(theta.cos() as f32) as f64;
            for j in 0..np {
                let phi = (j as f64 + 0.5) / np as f64 * 2.0 * std::f64::consts::PI;
                let l =
                    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
                sum += spot_texel(&texture, l, self.cutoff).as_dvec3() * falloff * w;
            }
        }
        self.pattern = Some((texture, sum.as_vec3()));
        self
    }

    /// ∫ falloff (times the pattern) dω: the power per unit intensity.
    pub fn solid_angle(&self) -> Color {
        match &self.pattern {
            None => Color::splat(self.solid_angle),
            Some((_, s)) => *s,
        }
    }

    /// The pattern's value towards local direction `l` (1 without one).
    #[inline]
    pub fn pattern_at(&self, l: Vec3) -> Color {
        match &self.pattern {
            None => Color::ONE,
            Some((t, _)) => spot_texel(t, l, self.cutoff),
        }
    }

    /// The share of the axis' intensity sent at angle acos(cos_theta).
    #[inline]
    pub fn falloff(&self, cos_theta: f32) -> f32 {
        if !(cos_theta > self.cos_cutoff) {
            return 0.0;
        }
        if cos_theta >= self.cos_beam {
            return 1.0;
        }
        ((self.cutoff - cos_theta.clamp(-1.0, 1.0).acos()) * self.inv_transition).clamp(0.0, 1.0)
    }

    /// Intensity towards unit world direction `dir`.
    #[inline]
    pub fn intensity_towards(&self, dir: Vec3) -> Color {
        let i = self.intensity * self.falloff(dir.dot(self.frame.n));
        match self.pattern {
            None => i,
            Some(_) if i.max_element() > 0.0 => i * self.pattern_at(self.frame.to_local(dir)),
            Some(_) => Color::ZERO,
        }
    }
}

impl Source for Spot {
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

    /// Uniform in the cone, weighted by the falloff (and the image).
    #[inline]
    fn sample_le(&self, _u_pos: Vec2, u_dir: Vec2) -> Emitted {
        let local = uniform_cone(u_dir, self.cos_cutoff);
        let dir = self.frame.to_world(local).normalize();
        // (I falloff / pdf) / (I ∫ falloff dω), pdf = 1 / cone's solid angle.
        let cone = 2.0 * PI * (1.0 - self.cos_cutoff);
        let solid = self.solid_angle();
        let weight = if solid.max_element() > 0.0 {
            self.pattern_at(local) * self.falloff(local.z) * cone / solid.max(Color::splat(1e-30))
        } else {
            Color::ZERO
        };
        Emitted { ray: Ray::new(self.position, dir), departure: None, weight }
    }

    fn pdf_le(&self, ray: &Ray) -> (f32, f32) {
        let inside = ray.dir.dot(self.frame.n) >= self.cos_cutoff;
        (1.0, if inside { uniform_cone_pdf(self.cos_cutoff) } else { 0.0 })
    }

    #[inline]
    fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed> {
        aimed_from(self.position, None, aim, rng, |dir| Some(self.intensity_towards(dir.normalize())))
    }

    fn power(&self) -> Color {
        self.solid_angle() * self.intensity
    }

    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        Some((self.position, self.position))
    }

    /// Full out to the beam, then falling to the cutoff.
    fn light_bounds(&self) -> Option<LightBounds> {
        let (p, phi) = (self.position, self.power().max_element());
        let cos_e = (self.cutoff - self.cos_beam.clamp(-1.0, 1.0).acos()).max(0.0).cos();
        Some(LightBounds { lo: p, hi: p, phi, w: self.frame.n, cos_o: self.cos_beam, cos_e })
    }

    fn moved(&mut self, origin: Vec3, scale: f32) {
        self.position = (self.position - origin) * scale;
        self.intensity *= scale * scale;
    }

    fn describe(&self) -> String {
        format!("the spot light at {}", self.position)
    }

    fn mitsuba(&self) -> Result<MitsubaEmitter, String> {
        if self.pattern.is_some() {
            return Err("a spot light's texture: its export to Mitsuba 3 is not written yet".to_string());
        }
        let axis = self.frame.n;
        let up = if axis.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
        Ok(MitsubaEmitter {
            plugin: "spot",
            params: vec![
                ("to_world", MitsubaParam::LookAt { origin: self.position, target: self.position + axis, up }),
                ("intensity", MitsubaParam::Rgb(self.intensity)),
                ("cutoff_angle", MitsubaParam::Float(self.cutoff_deg)),
                ("beam_width", MitsubaParam::Float(self.beam_deg)),
            ],
        })
    }
}
