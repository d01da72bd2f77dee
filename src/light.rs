//! Lights: a closed set. Area lights (a one-sided Lambertian disk, or any
//! triangle made emissive) are primitives too: camera rays see them and
//! photons stop on them. Point and directional lights are the Whitted
//! course's delta lights: they are never hit, only sampled.
//!
//! Every light answers two questions with the same geometry, so that shadow
//! rays and photons agree on its power: the light arriving at a point from a
//! sample of the light ([`Light::incident`]), and where a photon starts
//! ([`Light::emit`]). Each also answers the density with which its shadow
//! rays choose a direction ([`Light::pdf_around`]), which multiple
//! importance sampling at glossy surfaces weighs them by.

use crate::envmap::EnvMap;
use crate::math::{Color, Frame, Ray, Vertex};
use crate::sampling::{concentric_disk, cosine_hemisphere, uniform_cone, uniform_triangle};
use crate::shape::{Departure, Disk, RayShear, Triangle};
use crate::texture::{SurfacePoint, Texture};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

/// The surface of an area light.
#[derive(Clone, Copy, Debug)]
pub enum Emitting {
    Disk(Disk),
    Triangle(Triangle),
}

impl Emitting {
    pub fn area(&self) -> f32 {
        match self {
            Emitting::Disk(d) => d.area(),
            Emitting::Triangle(t) => t.area(),
        }
    }

    /// The side that emits.
    pub fn normal(&self) -> Vec3 {
        match self {
            Emitting::Disk(d) => d.normal,
            Emitting::Triangle(t) => t.normal,
        }
    }

    /// Any point of the surface (the plane's reference point).
    pub fn anchor(&self) -> Vertex {
        match self {
            Emitting::Disk(d) => d.center,
            Emitting::Triangle(t) => t.v0,
        }
    }

    /// Where a ray meets the surface (either side), if it does.
    fn distance(&self, ray: &Ray) -> Option<f32> {
        match self {
            Emitting::Disk(d) => d.distance(ray, f32::INFINITY),
            Emitting::Triangle(t) => t.distance(ray, &RayShear::new(ray), f32::INFINITY).map(|(t, _, _)| t),
        }
    }
}

/// A one-sided Lambertian emitter: of constant radiance, or of an image's
/// over a triangle (Mitsuba's area emitter with a radiance texture).
#[derive(Clone, Debug)]
pub struct AreaLight {
    pub surface: Emitting,
    /// The radiance; with a pattern, its mean over the surface.
    pub radiance: Color,
    /// Index of the surface's primitive in the scene (shadow rays ignore it).
    pub prim: u32,
    frame: Frame,
    pattern: Option<Arc<AreaPattern>>,
}

/// An image's radiance over a triangle light: the texture, the triangle's
/// texture coordinates at its corners.
#[derive(Clone, Debug)]
pub struct AreaPattern {
    pub texture: Texture,
    pub uv: [Vec2; 3],
}

impl AreaPattern {
    /// The radiance at barycentrics `b` (of the second and third corners).
    #[inline]
    pub fn at(&self, b: Vec2) -> Color {
        let uv = self.uv[0] * (1.0 - b.x - b.y) + self.uv[1] * b.x + self.uv[2] * b.y;
        self.texture.eval(&SurfacePoint { uv, prim: 0, bary: b }).max(Color::ZERO)
    }

    /// The mean radiance over the triangle, estimated at 64 stratified
    /// points: it only normalises (photons and light choices are weighted
    /// by the radiance where they start over it), so it must only not be
    /// zero where the image is not; a floor of 1e-3 of the image's largest
    /// value sees to that.
    fn mean(&self) -> Color {
        let n = 8;
        let mut sum = glam::DVec3::ZERO;
        for j in 0..n {
            for i in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                sum += self.at(uniform_triangle(u)).as_dvec3();
            }
        }
        (sum / (n * n) as f64).as_vec3().max(Color::splat(1e-3 * self.texture.max().max(0.0)))
    }
}

/// A point on an area light, chosen for a shadow ray.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub point: Vertex,
    pub normal: Vec3,
    /// pdf with respect to the light's area.
    pub pdf_area: f32,
    /// The radiance the light leaves there.
    pub radiance: Color,
}

impl AreaLight {
    pub fn new(surface: Emitting, radiance: Color, prim: u32) -> Self {
        AreaLight { surface, radiance, prim, frame: Frame::from_normal(surface.normal()), pattern: None }
    }

    /// The light with an image's radiance over its triangle; its
    /// `radiance` becomes the image's mean there.
    pub fn with_pattern(mut self, pattern: Arc<AreaPattern>) -> Self {
        if let Emitting::Triangle(_) = self.surface {
            self.radiance = pattern.mean();
            self.pattern = Some(pattern);
        }
        self
    }

    /// The radiance leaving at barycentrics `b` of a triangle light
    /// (towards its front).
    #[inline]
    pub fn radiance_at(&self, b: Vec2) -> Color {
        match &self.pattern {
            None => self.radiance,
            Some(p) => p.at(b),
        }
    }

    pub fn area(&self) -> f32 {
        self.surface.area()
    }

    /// Radiance leaving the light towards `-dir` for a ray travelling along
    /// `dir`; zero from the back side.
    pub fn radiance_towards(&self, dir: Vec3) -> Color {
        if dir.dot(self.surface.normal()) < 0.0 {
            self.radiance
        } else {
            Color::ZERO
        }
    }

    /// The density per solid angle, seen from `p`, with which
    /// [`Light::incident`] draws the direction towards the light's point
    /// `y`: |y - p|² / (cos_l area), zero where `p` sees the back.
    #[inline]
    pub fn pdf_at(&self, p: Vertex, y: Vertex) -> f32 {
        let to = y - p;
        let dist2 = to.length_squared();
        let cos_l = -to.dot(self.surface.normal()) / dist2.sqrt();
        if !(cos_l > 0.0 && dist2 > 0.0) {
            return 0.0;
        }
        dist2 / (cos_l * self.area())
    }

    /// Uniform point on the surface (pdf 1 / area).
    #[inline]
    pub fn sample_point(&self, u: Vec2) -> LightSample {
        let (point, radiance) = match self.surface {
            Emitting::Disk(disk) => {
                let d = concentric_disk(u) * disk.radius;
                (disk.center + self.frame.s * d.x + self.frame.t * d.y, self.radiance)
            }
            Emitting::Triangle(t) => {
                let b = uniform_triangle(u);
                (t.v0 * (1.0 - b.x - b.y) + t.v1 * b.x + t.v2 * b.y, self.radiance_at(b))
            }
        };
        LightSample { point, normal: self.surface.normal(), pdf_area: 1.0 / self.area(), radiance }
    }
}

/// Light arriving at a point from one sample of a light.
#[derive(Clone, Copy, Debug)]
pub struct Incident {
    /// Unit direction from the point towards the light sample.
    pub dir: Vec3,
    /// Where the shadow ray ends: the sample point (`None`: a directional
    /// light, unoccluded only if nothing lies anywhere along `dir`).
    pub target: Option<Vertex>,
    /// What multiplies BRDF x cos at the point: for an area light
    /// L cos_l / (d^2 pdf_A), for a point light I / (d + d0)^falloff, for a
    /// directional light its irradiance. The course's `I`.
    pub intensity: Color,
    /// The light's own primitive, which the shadow ray must not count.
    pub prim: Option<u32>,
}

/// A light of the scene.
#[derive(Clone, Debug)]
pub enum Light {
    Area(AreaLight),
    /// Emits `intensity` (W/sr) equally in every direction; the Whitted
    /// course dims it as 1 / (d + dead_distance)^falloff (physical: 2, 0).
    Point {
        position: Vertex,
        intensity: Color,
        falloff: f32,
        dead_distance: f32,
    },
    /// Parallel light travelling along unit `direction`, of irradiance
    /// `irradiance` on a surface facing it. Photons start on a disk facing
    /// the light that covers the scene (`reach`: its centre and radius).
    Directional {
        direction: Vec3,
        irradiance: Color,
        reach: (Vertex, f32),
    },
    /// A point emitting `intensity` (W/sr) into a cone (Mitsuba's `spot`).
    Spot(Spot),
    /// Radiance arriving equally from every direction at infinity
    /// (Mitsuba's `constant`). Photons start on a disk facing their
    /// direction that covers the scene's bounding sphere (`center`,
    /// `radius`), outside it.
    Constant {
        radiance: Color,
        center: Vertex,
        radius: f32,
    },
    /// A pinhole projecting irradiance through a frustum (Mitsuba's
    /// `projector`).
    Projector(Projector),
    /// Radiance from an environment map at infinity (Mitsuba's `envmap`),
    /// photons from a disk as for [`Light::Constant`].
    Envmap {
        map: std::sync::Arc<EnvMap>,
        center: Vertex,
        radius: f32,
    },
}

/// A projector at `position` shining along `axes[2]` through the frustum
/// |x / z| <= tan_x, |y / z| <= tan_y of its frame, with the radiant
/// intensity Mitsuba 3 gives it (src/emitters/projector.cpp): π E s / cos³θ,
/// so that a plane at unit distance facing it receives the same light
/// wherever the frustum reaches it.
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

    pub fn cos_cutoff(&self) -> f32 {
        self.cos_cutoff
    }

    pub fn beam_deg(&self) -> f32 {
        self.cos_beam.clamp(-1.0, 1.0).acos().to_degrees()
    }
}

impl Light {
    /// Whether the light is an ideal point or direction: one sample is exact.
    pub fn is_delta(&self) -> bool {
        !matches!(self, Light::Area(_) | Light::Constant { .. } | Light::Envmap { .. })
    }

    /// The area light, if this is one.
    pub fn area(&self) -> Option<&AreaLight> {
        match self {
            Light::Area(a) => Some(a),
            _ => None,
        }
    }

    /// Whether every sample of the light certainly sends nothing to `p`: the
    /// emitting side of a one-sided area light faces away from it.
    #[inline]
    pub fn faces_away(&self, p: Vertex) -> bool {
        match self {
            Light::Area(a) => (p - a.surface.anchor()).dot(a.surface.normal()) <= 0.0,
            _ => false,
        }
    }

    /// Light arriving at `p` from the sample `u` of the light; `None` when
    /// that sample sends nothing towards `p`.
    #[inline]
    pub fn incident(&self, p: Vertex, u: Vec2) -> Option<Incident> {
        match *self {
            Light::Area(ref a) => {
                let s = a.sample_point(u);
                let to = s.point - p;
                let dist2 = to.length_squared();
                if !(dist2 > 0.0) {
                    return None;
                }
                let dir = to / dist2.sqrt();
                let cos_l = -dir.dot(s.normal);
                if !(cos_l > 0.0) {
                    return None;
                }
                let intensity = s.radiance * (cos_l / (dist2 * s.pdf_area));
                Some(Incident { dir, target: Some(s.point), intensity, prim: Some(a.prim) })
            }
            Light::Point { position, intensity, falloff, dead_distance } => {
                let to = position - p;
                let dist = to.length();
                if !(dist > 0.0) {
                    return None;
                }
                let scale = (dist + dead_distance).powf(-falloff);
                let intensity = intensity * scale;
                intensity.is_finite().then_some(Incident {
                    dir: to / dist,
                    target: Some(position),
                    intensity,
                    prim: None,
                })
            }
            Light::Directional { direction, irradiance, .. } => {
                Some(Incident { dir: -direction, target: None, intensity: irradiance, prim: None })
            }
            Light::Envmap { ref map, .. } => {
                let (dir, pdf) = map.sample(u);
                (pdf > 0.0).then(|| Incident { dir, target: None, intensity: map.eval(dir) / pdf, prim: None })
            }
            Light::Constant { radiance, .. } => {
                // Uniform over the sphere (pdf 1 / 4π); `incident_around`
                // samples the hemisphere a surface sees instead.
                let dir = uniform_cone(u, -1.0).normalize();
                Some(Incident { dir, target: None, intensity: radiance * (4.0 * PI), prim: None })
            }
            Light::Projector(ref pr) => {
                let to = pr.position - p;
                let dist2 = to.length_squared();
                if !(dist2 > 0.0) {
                    return None;
                }
                let dir = to / dist2.sqrt();
                let intensity = pr.intensity_towards(-dir) / dist2;
                (intensity.is_finite() && intensity.max_element() > 0.0).then_some(Incident {
                    dir,
                    target: Some(pr.position),
                    intensity,
                    prim: None,
                })
            }
            Light::Spot(ref spot) => {
                let to = spot.position - p;
                let dist2 = to.length_squared();
                if !(dist2 > 0.0) {
                    return None;
                }
                let dir = to / dist2.sqrt();
                let intensity = spot.intensity_towards(-dir) / dist2;
                (intensity.is_finite() && intensity.max_element() > 0.0).then_some(Incident {
                    dir,
                    target: Some(spot.position),
                    intensity,
                    prim: None,
                })
            }
        }
    }

    /// As [`Self::incident`], for a surface at `p` whose reflecting side
    /// faces unit `n`: light from everywhere is sampled by the cosine about
    /// `n` (pdf cos / π), so that an unoccluded diffuse point's estimate has
    /// no variance; every other light as `incident`.
    #[inline]
    pub fn incident_around(&self, p: Vertex, n: Vec3, u: Vec2) -> Option<Incident> {
        match *self {
            Light::Constant { radiance, .. } => {
                let local = cosine_hemisphere(u);
                if !(local.z > 0.0) {
                    return None;
                }
                let dir = Frame::from_normal(n).to_world(local).normalize();
                Some(Incident { dir, target: None, intensity: radiance * (PI / local.z), prim: None })
            }
            _ => self.incident(p, u),
        }
    }

    /// The density per solid angle with which [`Self::incident_around`]
    /// (at `p`, facing `n`) returns unit direction `dir`: an area light's
    /// where `dir` meets its front, light from everywhere's by its own
    /// sampling; zero where it never returns `dir`, and for the delta
    /// lights, whose directions have no density (no other sampling finds
    /// them).
    pub fn pdf_around(&self, p: Vertex, n: Vec3, dir: Vec3) -> f32 {
        match *self {
            Light::Area(ref a) => a.surface.distance(&Ray::new(p, dir)).map_or(0.0, |t| a.pdf_at(p, p + t * dir)),
            Light::Constant { .. } => dir.dot(n).max(0.0) / PI,
            Light::Envmap { ref map, .. } => map.pdf(dir),
            _ => 0.0,
        }
    }

    /// [`Self::pdf_around`] of a sample `incident_around` returned.
    #[inline]
    pub fn pdf_of(&self, p: Vertex, n: Vec3, inc: &Incident) -> f32 {
        match (self, inc.target) {
            (Light::Area(a), Some(y)) => a.pdf_at(p, y),
            _ => self.pdf_around(p, n, inc.dir),
        }
    }

    /// Radiance arriving from unit direction `towards` from light at
    /// infinity (constant sky, environment map); zero for every other
    /// light.
    #[inline]
    pub fn radiance_from_infinity(&self, towards: Vec3) -> Color {
        match *self {
            Light::Constant { radiance, .. } => radiance,
            Light::Envmap { ref map, .. } => map.eval(towards),
            _ => Color::ZERO,
        }
    }

    /// Total emitted power per channel.
    pub fn power(&self) -> Color {
        match *self {
            Light::Area(ref a) => PI * a.area() * a.radiance,
            Light::Point { intensity, .. } => 4.0 * PI * intensity,
            Light::Directional { irradiance, reach, .. } => PI * reach.1 * reach.1 * irradiance,
            Light::Spot(ref s) => s.solid_angle() * s.intensity,
            // Through the disk πR², from every direction: L 4π πR².
            Light::Constant { radiance, radius, .. } => radiance * (4.0 * PI * PI * radius * radius),
            Light::Envmap { ref map, radius, .. } => map.total() * (PI * radius * radius),
            // dω = cos³θ dA on the plane z = 1: the frustum's area there.
            Light::Projector(ref p) => p.scaled * p.mean() * (4.0 * p.tan_x * p.tan_y),
        }
    }

    /// A photon's start with the light's natural distribution (area lights:
    /// uniform position, cosine direction; point lights: uniform direction;
    /// directional: uniform on the covering disk). With these pdfs every
    /// photon of N carries exactly power / N. The departure names the
    /// light's primitive, if it has one. The third value multiplies that
    /// power, per channel, where the direction is not drawn in proportion
    /// to the light's intensity (a spot's falloff: uniform in its cone,
    /// weighted; an environment map's colours).
    #[inline]
    pub fn emit(&self, u_pos: Vec2, u_dir: Vec2) -> (Ray, Option<Departure>, Color) {
        match *self {
            Light::Area(ref a) => {
                let s = a.sample_point(u_pos);
                // Unit to rounding without normalising (`Frame::to_world`):
                // the first ray waits on it.
                let dir = a.frame.to_world(cosine_hemisphere(u_dir));
                // An image's radiance over its mean, which the power holds.
                let weight = match a.pattern {
                    None => Color::ONE,
                    Some(_) => s.radiance / a.radiance.max(Color::splat(1e-30)),
                };
                (Ray::new(s.point, dir), Some(Departure { prim: a.prim, outward: true }), weight)
            }
            Light::Point { position, .. } => {
                (Ray::new(position, uniform_cone(u_dir, -1.0).normalize()), None, Color::ONE)
            }
            Light::Directional { direction, reach, .. } => {
                let frame = Frame::from_normal(direction);
                let d = concentric_disk(u_pos) * reach.1;
                (Ray::new(reach.0 + frame.s * d.x + frame.t * d.y, direction), None, Color::ONE)
            }
            Light::Envmap { ref map, center, radius } => {
                // A direction drawn from the map; its photon carries
                // L / (pdf ∫ L dω) of the mean share, per channel.
                let (towards, pdf) = map.sample(u_dir);
                let dir = -towards;
                let total = map.total();
                let l = map.eval(towards);
                let weight = Color::new(
                    if total.x > 0.0 { l.x / (pdf * total.x) } else { 0.0 },
                    if total.y > 0.0 { l.y / (pdf * total.y) } else { 0.0 },
                    if total.z > 0.0 { l.z / (pdf * total.z) } else { 0.0 },
                );
                let origin = center - dir * (2.0 * radius);
                let frame = Frame::from_normal(dir);
                let d = concentric_disk(u_pos) * radius;
                let weight = if pdf > 0.0 && weight.is_finite() { weight } else { Color::ZERO };
                (Ray::new(origin + frame.s * d.x + frame.t * d.y, dir), None, weight)
            }
            Light::Constant { center, radius, .. } => {
                // Travelling along a uniform direction, from a uniform
                // point of the disk facing it beyond the bounding sphere.
                let dir = uniform_cone(u_dir, -1.0).normalize();
                let origin = center - dir * (2.0 * radius);
                let frame = Frame::from_normal(dir);
                let d = concentric_disk(u_pos) * radius;
                (Ray::new(origin + frame.s * d.x + frame.t * d.y, dir), None, Color::ONE)
            }
            Light::Projector(ref p) => {
                // Uniform on the frustum's window at z = 1: in proportion to
                // the intensity, as dω = cos³θ dA.
                let (x, y) = ((2.0 * u_dir.x - 1.0) * p.tan_x, (2.0 * u_dir.y - 1.0) * p.tan_y);
                let dir = (p.axes[0] * x + p.axes[1] * y + p.axes[2]).normalize();
                let weight = match &p.pattern {
                    None => Color::ONE,
                    Some(_) => p.pattern_at(Vec3::new(x, y, 1.0)) / p.mean().max(Color::splat(1e-30)),
                };
                (Ray::new(p.position, dir), None, weight)
            }
            Light::Spot(ref s) => {
                let local = uniform_cone(u_dir, s.cos_cutoff);
                let dir = s.frame.to_world(local).normalize();
                // (I falloff / pdf) / (I ∫ falloff dω), pdf = 1 / cone's solid angle.
                let cone = 2.0 * PI * (1.0 - s.cos_cutoff);
                let solid = s.solid_angle();
                let weight = if solid.max_element() > 0.0 {
                    s.pattern_at(local) * s.falloff(local.z) * cone / solid.max(Color::splat(1e-30))
                } else {
                    Color::ZERO
                };
                (Ray::new(s.position, dir), None, weight)
            }
        }
    }
}

/// The disk from which a directional light's photons start: facing the
/// light, centred on the scene's bounding sphere, outside it.
pub fn directional_reach(direction: Vec3, lo: Vec3, hi: Vec3) -> (Vertex, f32) {
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo) * 0.5).length().max(f32::MIN_POSITIVE) * 1.001;
    (center - direction * (2.0 * radius), radius)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Irradiance on the axis at height h below a Lambertian disk of radius r:
    /// E = pi L r^2 / (r^2 + h^2). Estimate it by area sampling.
    #[test]
    fn disk_irradiance_on_axis_matches_closed_form() {
        let light = Light::Area(AreaLight::new(
            Emitting::Disk(Disk { center: Vec3::new(8.0, 0.0, 4.999), normal: -Vec3::Z, radius: 1.0 }),
            Color::splat(10.0),
            0,
        ));
        let mut rng = crate::sampling::stream(7, crate::sampling::Domain::Camera, 0);
        for h in [0.5f32, 2.0, 9.999] {
            let x = Vec3::new(8.0, 0.0, 4.999) - h * Vec3::Z;
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                if let Some(inc) = light.incident(x, crate::sampling::next_2d(&mut rng)) {
                    sum += (inc.intensity.x * inc.dir.dot(Vec3::Z)) as f64;
                }
            }
            let est = sum / n as f64;
            let exact = (PI * 10.0 / (1.0 + h * h)) as f64;
            assert!((est - exact).abs() / exact < 0.01, "h={h}: {est} vs {exact}");
        }
        // The spec's check: floor radiance below the light, direct only.
        let h = 4.999f64 + 5.0;
        let floor = 0.8 / std::f64::consts::PI * std::f64::consts::PI * 10.0 / (1.0 + h * h);
        assert!((floor - 0.07922).abs() < 1e-4);
    }

    /// An emissive triangle: irradiance at a point far away approaches
    /// L A cos / d^2, and the samples cover the triangle uniformly (mean at
    /// the centroid).
    #[test]
    fn triangle_light_samples_uniformly_and_matches_far_field() {
        let t = Triangle::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0));
        let light = AreaLight::new(Emitting::Triangle(t), Color::ONE, 0);
        let mut rng = crate::sampling::stream(3, crate::sampling::Domain::Camera, 1);
        let n = 100_000;
        let mut mean = Vec3::ZERO;
        for _ in 0..n {
            mean += light.sample_point(crate::sampling::next_2d(&mut rng)).point;
        }
        mean /= n as f32;
        let centroid = (t.v0 + t.v1 + t.v2) / 3.0;
        assert!((mean - centroid).length() < 0.01, "{mean} vs {centroid}");
        let x = centroid + t.normal * 1000.0;
        let inc = Light::Area(light.clone()).incident(x, Vec2::splat(0.3)).unwrap();
        let want = 1.0 / 1000.0f32.powi(2);
        assert!((inc.intensity.x - want).abs() < 1e-3 * want);
        // From behind, nothing.
        assert!(Light::Area(light).incident(centroid - t.normal, Vec2::splat(0.3)).is_none());
    }

    #[test]
    fn point_light_dims_with_the_course_falloff() {
        let l = Light::Point { position: Vec3::ZERO, intensity: Color::splat(8.0), falloff: 1.0, dead_distance: 2.0 };
        let inc = l.incident(Vec3::new(0.0, 6.0, 0.0), Vec2::ZERO).unwrap();
        assert!((inc.intensity.x - 1.0).abs() < 1e-6);
        assert!((inc.dir + Vec3::Y).length() < 1e-6);
    }
}
