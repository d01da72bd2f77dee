//! Lights: a closed set, one kind per file, each answering for itself
//! through [`Source`]. Area lights (a one-sided Lambertian disk, or any
//! triangle made emissive) are primitives too: camera rays see them and
//! photons stop on them. Point, spot, projector and directional lights are
//! delta lights: they are never hit, only sampled. Light from everywhere
//! (a constant sky, an environment map) arrives from infinity.
//!
//! A light answers, with the same geometry, the questions of pbrt-v4's
//! light interface (Pharr, Jakob, Humphreys, *pbrt*, 4th ed., §12.1): the
//! light arriving at a point from a sample of it (`sample_li`, pbrt's
//! SampleLi) and the density of that sample per solid angle (`pdf_li`,
//! PDF_Li), which multiple importance sampling weighs shadow rays by; a
//! photon's start (`sample_le`, SampleLe) and its densities of position and
//! direction (`pdf_le`, PDF_Le); a photon's start aimed at a cone or a disk
//! the photon pass names (`sample_le_towards`: caustic photons); its power.
//! Shadow rays and photons agree on the power because they share one
//! geometry.
//!
//! To add a light: a file beside these implementing [`Source`], its
//! variant in [`Light`] and its line in `each!`, and the table that reads
//! it in a scene front-end (notes/architecture.md).

mod area;
mod bounds;
mod directional;
mod environment;
pub mod infinity;
mod point;
mod projector;
mod sampler;
mod sky;
mod spot;

pub use area::{AreaLight, AreaPattern, Emitting, LightSample};
pub use bounds::LightBounds;
pub use directional::Directional;
pub use environment::Environment;
pub use point::PointLight;
pub use projector::Projector;
pub use sampler::{draws, LightSampler};
pub use sky::Constant;
pub use spot::Spot;

use crate::math::{Color, Frame, Ray, Vertex};
use crate::sampling::{next_2d, Rng};
use crate::shape::Departure;
use glam::{Vec2, Vec3};

/// Light arriving at a point from one sample of a light.
#[derive(Clone, Copy, Debug)]
pub struct Incident {
    /// Unit direction from the point towards the light sample.
    pub dir: Vec3,
    /// Where the shadow ray ends: the sample point (`None`: light from
    /// infinity, unoccluded only if nothing lies anywhere along `dir`).
    pub target: Option<Vertex>,
    /// What multiplies BRDF x cos at the point: for an area light
    /// L cos_l / (d^2 pdf_A), for a point light I / (d + d0)^falloff, for a
    /// directional light its irradiance. The course's `I`.
    pub intensity: Color,
    /// The light's own primitive, which the shadow ray must not count.
    pub prim: Option<u32>,
}

/// A photon leaving its light with the light's own distribution.
#[derive(Clone, Copy, Debug)]
pub struct Emitted {
    pub ray: Ray,
    /// The light's primitive, which the first ray leaves.
    pub departure: Option<Departure>,
    /// What multiplies power / N, per channel, where the start is not drawn
    /// in proportion to what the light sends (a spot's falloff, an image's
    /// colours): one on average.
    pub weight: Color,
}

/// A photon aimed by the photon pass ([`Aim`]): its ray, and what it
/// carries before the density of its aiming divides it: the radiant
/// intensity towards its direction (from a point), or the irradiance across
/// its direction (parallel light).
#[derive(Clone, Copy, Debug)]
pub struct Aimed {
    pub ray: Ray,
    pub departure: Option<Departure>,
    pub intensity: Color,
    /// The density of the aimed choice: per solid angle from a point, per
    /// area across parallel light.
    pub pdf: f32,
}

/// Where the photon pass aims photons (caustic photons at mirrors and
/// glass). A light from a point draws a direction from it; a light from
/// infinity draws its direction itself, then a start across it.
pub trait Aim {
    /// A direction from `origin` towards the targets, and its density per
    /// solid angle.
    fn direction_from(&self, origin: Vertex, u: Vec2) -> (Vec3, f32);
    /// A start for light travelling along `direction` from the plane
    /// through `plane` across it, and its density per unit area.
    fn origin_across(&self, direction: Vec3, plane: Vertex, u: Vec2) -> (Vertex, f32);
}

/// What every light answers. Defaults serve the lights that do not have
/// the property (a delta light has no density, a light at a point needs no
/// placing, only light from infinity is met by a ray that leaves).
pub trait Source {
    /// Light arriving at `p`, on a surface whose reflecting side faces
    /// unit `n`, from the sample `u` of the light; `None` where that sample
    /// sends nothing towards `p`.
    fn sample_li(&self, p: Vertex, n: Vec3, u: Vec2) -> Option<Incident>;

    /// The density per solid angle with which `sample_li` (at `p`, facing
    /// `n`) returns unit direction `dir`; zero where it never does, and for
    /// delta lights, whose directions have no density.
    fn pdf_li(&self, _p: Vertex, _n: Vec3, _dir: Vec3) -> f32 {
        0.0
    }

    /// [`Self::pdf_li`] of a sample `sample_li` returned.
    fn pdf_li_of(&self, p: Vertex, n: Vec3, inc: &Incident) -> f32 {
        self.pdf_li(p, n, inc.dir)
    }

    /// Whether the light draws shadow rays differently where a cosine
    /// strategy shares its light by MIS ([`Self::sample_li_shared`]).
    fn compensates(&self) -> bool {
        false
    }

    /// [`Self::sample_li`] for shadow rays whose directions a cosine
    /// strategy at `p` also draws (MIS): a light from everywhere may leave
    /// its dim parts to that strategy (MIS compensation). The same as
    /// `sample_li` unless [`Self::compensates`].
    fn sample_li_shared(&self, p: Vertex, n: Vec3, u: Vec2) -> Option<Incident> {
        self.sample_li(p, n, u)
    }

    /// The density of [`Self::sample_li_shared`].
    fn pdf_li_shared(&self, p: Vertex, n: Vec3, dir: Vec3) -> f32 {
        self.pdf_li(p, n, dir)
    }

    /// A photon's start with the light's natural distribution (area lights:
    /// uniform position, cosine direction; point lights: uniform direction;
    /// light from infinity: uniform on a disk across it that covers the
    /// scene). With these densities every photon of N carries power / N
    /// times its weight.
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Emitted;

    /// The densities with which `sample_le` starts `ray`: of its origin
    /// (per area; 1 for a light at a point) and of its direction (per
    /// solid angle; 1 for a single direction).
    fn pdf_le(&self, ray: &Ray) -> (f32, f32);

    /// A photon's start aimed as `aim` says (its random numbers from `rng`).
    fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed>;

    /// As [`Self::sample_le_towards`], with two uniform points `u` of the
    /// caustic pass's low-discrepancy sequence ([`crate::sampling::photon_points`])
    /// for the light to spend where they stratify its caustic: light from
    /// infinity draws its direction from the first and its start on the
    /// aimed disk from the second. The other lights keep to `rng` (their
    /// photons, and the default room's image, as before).
    fn sample_le_towards_at(&self, aim: &impl Aim, _u: [Vec2; 2], rng: &mut Rng) -> Option<Aimed> {
        self.sample_le_towards(aim, rng)
    }

    /// Total emitted power per channel.
    fn power(&self) -> Color;

    /// Whether the light is an ideal point or direction: one sample is exact.
    fn is_delta(&self) -> bool {
        true
    }

    /// Whether every sample of the light certainly sends nothing to `p`.
    fn faces_away(&self, _p: Vertex) -> bool {
        false
    }

    /// Radiance arriving along unit direction `towards` from light at
    /// infinity.
    fn radiance_from_infinity(&self, _towards: Vec3) -> Color {
        Color::ZERO
    }

    /// The box the light occupies, which the scene's bounds hold (`None`:
    /// light from infinity).
    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        None
    }

    /// What bounds where and how much it emits, for the light hierarchy
    /// ([`LightSampler`]); `None`: light from infinity.
    fn light_bounds(&self) -> Option<LightBounds> {
        None
    }

    /// Takes its place around the scene's box (`lo`, `hi`): light from
    /// infinity starts its photons outside it.
    fn place(&mut self, _lo: Vec3, _hi: Vec3) {}

    /// The same light in a scene whose every point p becomes
    /// (p - `origin`) `scale` (`scale` > 0): positions move, and a light
    /// from a point scales its intensity by scale², which keeps the
    /// irradiance I / d² it gives.
    fn moved(&mut self, origin: Vec3, scale: f32);

    /// How a message names the light.
    fn describe(&self) -> String;

    /// The light as Mitsuba 3's emitter plugin (for the export), or why
    /// there is none.
    fn mitsuba(&self) -> Result<MitsubaEmitter, String> {
        Err(format!("{}: its export to Mitsuba 3 is not written yet", self.describe()))
    }
}

/// A light as a Mitsuba 3 `<emitter>`: its plugin name and parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct MitsubaEmitter {
    pub plugin: &'static str,
    pub params: Vec<(&'static str, MitsubaParam)>,
}

/// A parameter of a [`MitsubaEmitter`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MitsubaParam {
    Rgb(Color),
    Point(Vec3),
    Vector(Vec3),
    Float(f32),
    /// A `to_world` transform looking from `origin` at `target`.
    LookAt {
        origin: Vec3,
        target: Vec3,
        up: Vec3,
    },
}

/// A light of the scene.
#[derive(Clone, Debug)]
pub enum Light {
    Area(AreaLight),
    Point(PointLight),
    Directional(Directional),
    Spot(Spot),
    Constant(Constant),
    Projector(Projector),
    Envmap(Environment),
}

/// Calls `$body` with `$l` bound to the light's own kind.
macro_rules! each {
    ($light:expr, $l:ident => $body:expr) => {
        match $light {
            Light::Area($l) => $body,
            Light::Point($l) => $body,
            Light::Directional($l) => $body,
            Light::Spot($l) => $body,
            Light::Constant($l) => $body,
            Light::Projector($l) => $body,
            Light::Envmap($l) => $body,
        }
    };
}

impl Light {
    /// The area light, if this is one.
    pub fn area(&self) -> Option<&AreaLight> {
        match self {
            Light::Area(a) => Some(a),
            _ => None,
        }
    }

    /// See [`Source::sample_li`].
    #[inline]
    pub fn sample_li(&self, p: Vertex, n: Vec3, u: Vec2) -> Option<Incident> {
        each!(self, l => l.sample_li(p, n, u))
    }

    /// See [`Source::pdf_li`].
    pub fn pdf_li(&self, p: Vertex, n: Vec3, dir: Vec3) -> f32 {
        each!(self, l => l.pdf_li(p, n, dir))
    }

    /// See [`Source::pdf_li_of`].
    #[inline]
    pub fn pdf_li_of(&self, p: Vertex, n: Vec3, inc: &Incident) -> f32 {
        each!(self, l => l.pdf_li_of(p, n, inc))
    }

    /// See [`Source::compensates`].
    pub fn compensates(&self) -> bool {
        each!(self, l => l.compensates())
    }

    /// See [`Source::sample_li_shared`].
    pub fn sample_li_shared(&self, p: Vertex, n: Vec3, u: Vec2) -> Option<Incident> {
        each!(self, l => l.sample_li_shared(p, n, u))
    }

    /// See [`Source::pdf_li_shared`].
    pub fn pdf_li_shared(&self, p: Vertex, n: Vec3, dir: Vec3) -> f32 {
        each!(self, l => l.pdf_li_shared(p, n, dir))
    }

    /// See [`Source::sample_le`].
    #[inline]
    pub fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Emitted {
        each!(self, l => l.sample_le(u_pos, u_dir))
    }

    /// See [`Source::pdf_le`].
    pub fn pdf_le(&self, ray: &Ray) -> (f32, f32) {
        each!(self, l => l.pdf_le(ray))
    }

    /// See [`Source::sample_le_towards`].
    #[inline]
    pub fn sample_le_towards(&self, aim: &impl Aim, rng: &mut Rng) -> Option<Aimed> {
        each!(self, l => l.sample_le_towards(aim, rng))
    }

    /// See [`Source::sample_le_towards_at`].
    #[inline]
    pub fn sample_le_towards_at(&self, aim: &impl Aim, u: [Vec2; 2], rng: &mut Rng) -> Option<Aimed> {
        each!(self, l => l.sample_le_towards_at(aim, u, rng))
    }

    /// See [`Source::power`].
    pub fn power(&self) -> Color {
        each!(self, l => l.power())
    }

    /// See [`Source::is_delta`].
    #[inline]
    pub fn is_delta(&self) -> bool {
        each!(self, l => l.is_delta())
    }

    /// See [`Source::faces_away`].
    #[inline]
    pub fn faces_away(&self, p: Vertex) -> bool {
        each!(self, l => l.faces_away(p))
    }

    /// See [`Source::radiance_from_infinity`].
    #[inline]
    pub fn radiance_from_infinity(&self, towards: Vec3) -> Color {
        each!(self, l => l.radiance_from_infinity(towards))
    }

    /// See [`Source::bounds`].
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        each!(self, l => l.bounds())
    }

    /// See [`Source::light_bounds`].
    pub fn light_bounds(&self) -> Option<LightBounds> {
        each!(self, l => l.light_bounds())
    }

    /// See [`Source::place`].
    pub fn place(&mut self, lo: Vec3, hi: Vec3) {
        each!(self, l => l.place(lo, hi))
    }

    /// See [`Source::moved`].
    pub fn moved(&mut self, origin: Vec3, scale: f32) {
        each!(self, l => l.moved(origin, scale))
    }

    /// See [`Source::describe`].
    pub fn describe(&self) -> String {
        each!(self, l => l.describe())
    }

    /// See [`Source::mitsuba`].
    pub fn mitsuba(&self) -> Result<MitsubaEmitter, String> {
        each!(self, l => l.mitsuba())
    }
}

/// Places `lights` in a scene whose primitives span (`lo`, `hi`), and
/// returns the scene's box: the primitives' and the lights' own
/// (zero-sized at the origin where there is nothing). Light from infinity
/// starts its photons outside that box.
pub fn place_lights(lights: &mut [Light], mut lo: Vec3, mut hi: Vec3) -> (Vec3, Vec3) {
    for (a, b) in lights.iter().filter_map(Light::bounds) {
        lo = lo.min(a);
        hi = hi.max(b);
    }
    if !(lo.x <= hi.x) {
        (lo, hi) = (Vec3::ZERO, Vec3::ZERO);
    }
    for l in lights.iter_mut() {
        l.place(lo, hi);
    }
    (lo, hi)
}

/// A photon from `origin` aimed by `aim`, carrying the intensity
/// `intensity(dir)` sends along its direction (`None`: nothing).
#[inline]
fn aimed_from(
    origin: Vertex,
    departure: Option<Departure>,
    aim: &impl Aim,
    rng: &mut Rng,
    intensity: impl FnOnce(Vec3) -> Option<Color>,
) -> Option<Aimed> {
    let (dir, pdf) = aim.direction_from(origin, next_2d(rng));
    let intensity = intensity(dir)?;
    Some(Aimed { ray: Ray::new(origin, dir), departure, intensity, pdf })
}

/// A photon of parallel light along `direction`, of `irradiance` across
/// it, from the plane through `plane`, started where `aim` says.
#[inline]
fn aimed_across(direction: Vec3, irradiance: Color, plane: Vertex, aim: &impl Aim, u: Vec2) -> Aimed {
    let (origin, pdf) = aim.origin_across(direction, plane, u);
    Aimed { ray: Ray::new(origin, direction), departure: None, intensity: irradiance, pdf }
}

/// The disk from which parallel light's photons start: facing the light,
/// centred on the scene's bounding sphere, outside it.
pub fn directional_reach(direction: Vec3, lo: Vec3, hi: Vec3) -> (Vertex, f32) {
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo) * 0.5).length().max(f32::MIN_POSITIVE) * 1.001;
    (center - direction * (2.0 * radius), radius)
}

/// A uniform point of the disk of `radius` about `center` facing unit
/// `normal`.
#[inline]
fn disk_point(center: Vertex, normal: Vec3, radius: f32, u: Vec2) -> Vertex {
    let frame = Frame::from_normal(normal);
    let d = crate::sampling::concentric_disk(u) * radius;
    center + frame.s * d.x + frame.t * d.y
}

/// The density per area of [`disk_point`] at `p` (zero off the disk).
fn disk_pdf(center: Vertex, normal: Vec3, radius: f32, p: Vertex) -> f32 {
    let d = p - center;
    let across = d - normal * d.dot(normal);
    let r2 = radius * radius;
    if across.length_squared() <= r2 * (1.0 + 1e-4) && r2 > 0.0 {
        1.0 / (std::f32::consts::PI * r2)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::Disk;

    /// Every light answers through the enum as through its own kind.
    #[test]
    fn the_enum_answers_as_the_kind() {
        let disk = Disk { center: Vec3::new(0.0, 0.0, 2.0), normal: -Vec3::Z, radius: 0.5 };
        let light = Light::Area(AreaLight::new(Emitting::Disk(disk), Color::splat(3.0), 7));
        let Light::Area(a) = &light else { unreachable!() };
        assert_eq!(light.power(), a.power());
        assert!(!light.is_delta());
        assert!(light.faces_away(Vec3::new(0.0, 0.0, 3.0)));
        assert!(!light.faces_away(Vec3::ZERO));
        assert!(light.describe().contains("disk"));
    }
}
