//! An area light: a one-sided Lambertian disk or triangle, of constant
//! radiance or of an image's over a triangle (Mitsuba's area emitter with
//! a radiance texture). Its surface is a primitive of the scene too.

use super::{aimed_from, Aim, Aimed, Emitted, Incident, Light, LightBounds, Source};
use crate::math::{Color, Frame, Ray, Vertex};
use crate::sampling::{concentric_disk, cosine_hemisphere, next_2d, uniform_triangle, Rng};
use crate::shape::{Departure, Disk, RayShear, Shape, Triangle};
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

    /// The surface as a primitive's shape.
    pub fn shape(&self) -> Shape {
        match *self {
            Emitting::Disk(d) => Shape::Disk(d),
            Emitting::Triangle(t) => Shape::Triangle(t),
        }
    }

    /// The surface in a scene whose every point p becomes (p - `origin`)
    /// `scale`.
    fn moved(&self, origin: Vec3, scale: f32) -> Self {
        let at = |p: Vec3| (p - origin) * scale;
        match *self {
            Emitting::Disk(d) => Emitting::Disk(Disk { center: at(d.center), radius: d.radius * scale, ..d }),
            Emitting::Triangle(t) => Emitting::Triangle(Triangle::new(at(t.v0), at(t.v1), at(t.v2))),
        }
    }

    /// Where a ray meets the surface (either side), if it does.
    fn distance(&self, ray: &Ray) -> Option<f32> {
        match self {
            Emitting::Disk(d) => d.distance(ray, f32::INFINITY),
            Emitting::Triangle(t) => t.distance(ray, &RayShear::new(ray), f32::INFINITY).map(|(t, _, _)| t),
        }
    }

    /// Whether `p` lies on the surface (to a relative 1e-3 off its plane).
    fn holds(&self, p: Vertex) -> bool {
        let n = self.normal();
        let h = 1e-3 * (1.0 + p.abs().max_element());
        if (p - self.anchor()).dot(n).abs() > h {
            return false;
        }
        self.distance(&Ray::new(p + n * h, -n)).is_some()
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
    /// The material its surface reflects with (a glowing wall); `None`: a
    /// pure emitter, black to the light that reaches it.
    pub material: Option<u32>,
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
        AreaLight {
            surface,
            radiance,
            prim,
            material: None,
            frame: Frame::from_normal(surface.normal()),
            pattern: None,
        }
    }

    /// A light as a scene describes it, before the scene makes its surface
    /// a primitive ([`Self::placed`]).
    pub fn unplaced(surface: Emitting, radiance: Color, material: Option<u32>) -> Light {
        Light::Area(AreaLight { material, ..AreaLight::new(surface, radiance, u32::MAX) })
    }

    /// The light whose surface is primitive `prim` of the scene, with its
    /// image (or `pattern`, given by the scene's textures).
    pub fn placed(&self, prim: u32, pattern: Option<Arc<AreaPattern>>) -> Self {
        let light = AreaLight { material: self.material, ..AreaLight::new(self.surface, self.radiance, prim) };
        match pattern.or_else(|| self.pattern.clone()) {
            Some(p) => light.with_pattern(p),
            None => light,
        }
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
    /// [`Source::sample_li`] draws the direction towards the light's point
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

    fn departure(&self) -> Option<Departure> {
        Some(Departure { prim: self.prim, outward: true })
    }
}

impl Source for AreaLight {
    #[inline]
    fn sample_li(&self, p: Vertex, _n: Vec3, u: Vec2) -> Option<Incident> {
        let s = self.sample_point(u);
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
        Some(Incident { dir, target: Some(s.point), intensity, prim: Some(self.prim) })
    }

    /// Where `dir` meets the light's front.
    fn pdf_li(&self, p: Vertex, _n: Vec3, dir: Vec3) -> f32 {
        self.surface.distance(&Ray::new(p, dir)).map_or(0.0, |t| self.pdf_at(p, p + t * dir))
    }

    #[inline]
    fn pdf_li_of(&self, p: Vertex, n: Vec3, inc: &Incident) -> f32 {
        match inc.target {
            Some(y) => self.pdf_at(p, y),
            None => self.pdf_li(p, n, inc.dir),
        }
    }

    /// Uniform position, cosine direction.
    #[inline]
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Emitted {
        let s = self.sample_point(u_pos);
        // Unit to rounding without normalising (`Frame::to_world`): the
        // first ray waits on it.
        let dir = self.frame.to_world(cosine_hemisphere(u_dir));
        // An image's radiance over its mean, which the power holds.
        let weight = match self.pattern {
            None => Color::ONE,
            Some(_) => s.radiance / self.radiance.max(Color::splat(1e-30)),
        };
        Emitted { ray: Ray::new(s.point, dir), departure: self.departure(), weight }
    }

    fn pdf_le(&self, ray: &Ray) -> (f32, f32) {
        let pos = if self.surface.holds(ray.origin) { 1.0 / self.area() } else { 0.0 };
        (pos, ray.dir.dot(self.surface.normal()).max(0.0) / PI)
    }

    /// A uniform point, the direction drawn towards the aim: the intensity
    /// L cos A it carries is the light's as seen from that point.
    #[inline]
    fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed> {
        let s = self.sample_point(next_2d(rng));
        aimed_from(s.point, self.departure(), aim, rng, |dir| {
            let cos_emit = dir.dot(self.surface.normal());
            (cos_emit > 0.0).then(|| s.radiance * cos_emit * self.area())
        })
    }

    fn power(&self) -> Color {
        PI * self.area() * self.radiance
    }

    fn is_delta(&self) -> bool {
        false
    }

    /// The emitting side faces away from `p`.
    #[inline]
    fn faces_away(&self, p: Vertex) -> bool {
        (p - self.surface.anchor()).dot(self.surface.normal()) <= 0.0
    }

    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        Some(self.surface.shape().bounds())
    }

    /// Its normal, light leaving up to π/2 from it.
    fn light_bounds(&self) -> Option<LightBounds> {
        let (lo, hi) = self.surface.shape().bounds();
        let phi = self.power().max_element();
        Some(LightBounds { lo, hi, phi, w: self.surface.normal(), cos_o: 1.0, cos_e: 0.0 })
    }

    fn moved(&mut self, origin: Vec3, scale: f32) {
        let pattern = self.pattern.clone();
        let radiance = self.radiance;
        *self = AreaLight {
            material: self.material,
            ..AreaLight::new(self.surface.moved(origin, scale), radiance, self.prim)
        };
        self.pattern = pattern;
    }

    fn describe(&self) -> String {
        match self.surface {
            Emitting::Disk(d) => format!("the disk light at {}", d.center),
            Emitting::Triangle(t) => format!("the triangle light at {}", t.v0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::Light;

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
                if let Some(inc) = light.sample_li(x, Vec3::Z, crate::sampling::next_2d(&mut rng)) {
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
        let inc = light.sample_li(x, -t.normal, Vec2::splat(0.3)).unwrap();
        let want = 1.0 / 1000.0f32.powi(2);
        assert!((inc.intensity.x - want).abs() < 1e-3 * want);
        // From behind, nothing.
        assert!(light.sample_li(centroid - t.normal, t.normal, Vec2::splat(0.3)).is_none());
    }
}
