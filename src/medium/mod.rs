//! Participating media: fog, smoke, murky water. A medium fills the inside
//! or outside of shapes ([`Interface`], Mitsuba 3's `interior` and
//! `exterior`), and light travelling through it is absorbed and scattered
//! by its extinction σ_t = σ_s + σ_a (per unit length, per RGB channel),
//! its single-scattering albedo σ_s / σ_t and its phase function
//! ([`phase`]). As in Mitsuba 3 (src/media/homogeneous.cpp,
//! heterogeneous.cpp):
//!
//! * a **homogeneous** medium has one σ_t everywhere (its albedo may vary
//!   through a volume); its transmittance over a distance d is exactly
//!   exp(-σ_t d) (Beer–Lambert);
//! * a **heterogeneous** medium reads σ_t from a volume ([`volume`]: a
//!   constant or a `.vol` grid, [`vol_file`]) and has density only inside
//!   that volume's box; distances are sampled by delta tracking and
//!   transmittance estimated by ratio tracking (Woodcock et al. 1965;
//!   Novák et al. 2014), both unbiased, against local majorants: a grid's
//!   coarse cells each bound its own part ([`Majorants`]); a constant
//!   volume's is `scale` × its value.
//!
//! Both scale σ_t by `scale`. Where σ_t differs between channels, a
//! distance is drawn in one channel chosen in proportion to the path's
//! weight and weighed by the mixture of all channels' densities (spectral
//! MIS, as hero-wavelength sampling does; Wilkie et al. 2014), which
//! keeps every channel unbiased.

mod lit;
mod majorant;
pub mod phase;
mod segment;
pub mod vol_file;
pub mod volume;

pub use lit::{LitGrid, LitSegment};
pub use majorant::Majorants;
pub use phase::Phase;
pub use segment::Steps;
pub use vol_file::{VolError, VolGrid};
pub use volume::{Aabb, Filter, Grid, Volume, Wrap};

use crate::math::{Color, Ray};
use crate::sampling::Rng;
use glam::Vec3;
use rand::RngExt;
use std::ops::ControlFlow;

/// What a ray's flight through a medium ended in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Flight {
    /// The light scattered at distance `t`: the path's weight is
    /// multiplied by `weight` (transmittance × σ_s over the density of
    /// drawing `t`), then by the phase function's sample.
    Scattered { t: f32, weight: Color },
    /// The ray reached the end of its segment: its weight is multiplied by
    /// `weight` (transmittance over the chance of getting there).
    Passed { weight: Color },
}

/// A free-flight distance drawn in a homogeneous medium, with the
/// channels' chances it was drawn with.
#[derive(Clone, Copy, Debug)]
pub struct Distance {
    pub t: f32,
    q: Color,
}

/// A participating medium.
#[derive(Clone, Debug)]
pub struct Medium {
    /// σ_t as given (a heterogeneous medium's volume), before `scale`.
    pub sigma_t: Volume,
    pub albedo: Volume,
    pub scale: f32,
    pub phase: Phase,
    /// Whether shadow rays are cast from inside the medium (Mitsuba's
    /// `sample_emitters`; off, scattered light reaches a light only by the
    /// phase function's samples).
    pub sample_emitters: bool,
    kind: Kind,
    /// A grid's local majorants (`None`: the one majorant holds everywhere).
    majorants: Option<std::sync::Arc<Majorants>>,
    /// [`Self::scatters`], found once: a grid's largest value is a pass
    /// over all its cells, and every flight and camera segment asks.
    scatters: bool,
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    /// σ_t × scale, everywhere.
    Homogeneous { sigma_t: Color },
    /// Density only inside `bbox`, at most `majorant` in every channel.
    Heterogeneous { majorant: f32, bbox: Aabb },
}

impl Medium {
    /// Mitsuba's `homogeneous`: `sigma_t` a constant colour (a volume is
    /// refused), `albedo` any volume in [0, 1].
    pub fn homogeneous(sigma_t: Color, albedo: Volume, scale: f32, phase: Phase) -> Result<Medium, String> {
        check_coefficients(sigma_t.min_element(), sigma_t.max_element(), scale, &albedo)?;
        let scatters = scatters(&albedo, sigma_t.max_element(), scale);
        Ok(Medium {
            sigma_t: Volume::Constant { value: sigma_t, to_world: glam::Affine3A::IDENTITY },
            albedo,
            scale,
            phase,
            sample_emitters: true,
            kind: Kind::Homogeneous { sigma_t: sigma_t * scale },
            majorants: None,
            scatters,
        })
    }

    /// Mitsuba's `heterogeneous`: σ_t read from `sigma_t` inside its box.
    pub fn heterogeneous(sigma_t: Volume, albedo: Volume, scale: f32, phase: Phase) -> Result<Medium, String> {
        check_coefficients(sigma_t.min(), sigma_t.max(), scale, &albedo)?;
        let majorant = scale * sigma_t.max();
        let kind = Kind::Heterogeneous { majorant, bbox: sigma_t.bbox() };
        let majorants = match &sigma_t {
            Volume::Grid(g) => Some(std::sync::Arc::new(Majorants::new(g, scale, majorant))),
            Volume::Constant { .. } => None,
        };
        let scatters = scatters(&albedo, sigma_t.max(), scale);
        Ok(Medium { sigma_t, albedo, scale, phase, sample_emitters: true, kind, majorants, scatters })
    }

    pub fn is_homogeneous(&self) -> bool {
        matches!(self.kind, Kind::Homogeneous { .. })
    }

    /// Whether light can scatter in the medium (some albedo above zero);
    /// a medium that only absorbs is crossed, never scattered in.
    #[inline]
    pub fn scatters(&self) -> bool {
        self.scatters
    }

    /// The scaled extinction and scattering coefficients at `p`.
    #[inline]
    pub fn coefficients(&self, p: Vec3) -> (Color, Color) {
        let sigma_t = match self.kind {
            Kind::Homogeneous { sigma_t } => sigma_t,
            Kind::Heterogeneous { bbox, .. } => {
                if p.cmplt(bbox.lo).any() || p.cmpgt(bbox.hi).any() {
                    return (Color::ZERO, Color::ZERO);
                }
                self.sigma_t.eval(p) * self.scale
            }
        };
        (sigma_t, sigma_t * self.albedo.eval(p))
    }

    /// The same medium in a scene whose lengths are multiplied by `s`:
    /// coefficients per unit length divided by `s`.
    pub fn scaled(&self, s: f32) -> Medium {
        let (sigma_t, albedo) = (self.sigma_t.scaled(s), self.albedo.scaled(s));
        let m = match self.kind {
            Kind::Homogeneous { .. } => {
                Medium::homogeneous(sigma_t.constant().unwrap_or(Color::ZERO), albedo, self.scale / s, self.phase)
            }
            Kind::Heterogeneous { .. } => Medium::heterogeneous(sigma_t, albedo, self.scale / s, self.phase),
        };
        match m {
            Ok(mut m) => {
                m.sample_emitters = self.sample_emitters;
                m
            }
            Err(_) => self.clone(),
        }
    }

    /// Draws where light travelling along `ray` first interacts with the
    /// medium within `t_max` (which may be infinite): a scattering, or the
    /// segment's end. `throughput` is the path's weight so far, which
    /// chooses the channel distances are drawn in; zero channels are
    /// never chosen.
    #[inline]
    pub fn sample_flight(&self, ray: &Ray, t_max: f32, throughput: Color, rng: &mut Rng) -> Flight {
        if !self.scatters() {
            return Flight::Passed { weight: self.transmittance(ray, t_max, rng) };
        }
        match self.kind {
            Kind::Homogeneous { .. } => {
                let d = self.draw_distance(throughput, rng);
                if d.t < t_max {
                    Flight::Scattered { t: d.t, weight: self.scattered_at(&d, ray.at(d.t)) }
                } else {
                    Flight::Passed { weight: self.passed(&d, t_max) }
                }
            }
            Kind::Heterogeneous { majorant, bbox } => {
                let Some((t0, t1)) = bbox.clip(ray, t_max) else {
                    return Flight::Passed { weight: Color::ONE };
                };
                let mut w = Color::ONE;
                let mut end = None;
                self.tentative_collisions(majorant, ray, t0, t1, rng, |t, mu, rng| {
                    let p = ray.at(t);
                    let sigma_t = self.sigma_t.eval(p) * self.scale;
                    // A real collision with the path-weighted chance of
                    // σ_t / majorant, a null one with the rest; each
                    // weighed so that every channel stays unbiased.
                    let q = channel_weights(throughput * w);
                    let real = ((q * sigma_t).element_sum() / mu).clamp(0.0, 1.0);
                    if rng.random::<f32>() < real {
                        let sigma_s = sigma_t * self.albedo.eval(p);
                        end = Some(Flight::Scattered { t, weight: w * sigma_s / (mu * real) });
                        return ControlFlow::Break(());
                    }
                    let sigma_n = (Color::splat(mu) - sigma_t).max(Color::ZERO);
                    w *= sigma_n / (mu * (1.0 - real));
                    if w == Color::ZERO {
                        return ControlFlow::Break(());
                    }
                    ControlFlow::Continue(())
                });
                end.unwrap_or(Flight::Passed { weight: w })
            }
        }
    }

    /// A homogeneous medium's free flight drawn before the ray's surface is
    /// known (so that the surface is sought only closer than it): a
    /// distance from the channel chosen in proportion to `throughput`.
    /// [`Self::scattered_at`] weighs a scattering there,
    /// [`Self::passed`] a surface met first. Only for a medium that
    /// [`Self::is_homogeneous`] and [`Self::scatters`].
    #[inline]
    pub fn draw_distance(&self, throughput: Color, rng: &mut Rng) -> Distance {
        let Kind::Homogeneous { sigma_t } = self.kind else {
            return Distance { t: f32::INFINITY, q: Color::splat(1.0 / 3.0) };
        };
        let q = channel_weights(throughput);
        let (u1, u2) = (rng.random::<f32>(), rng.random::<f32>());
        let c = if u1 < q.x {
            0
        } else if u1 < q.x + q.y {
            1
        } else {
            2
        };
        let t = if sigma_t[c] > 0.0 { -(1.0 - u2).ln() / sigma_t[c] } else { f32::INFINITY };
        Distance { t, q }
    }

    /// The weight of scattering at the drawn distance, at point `p`:
    /// transmittance × σ_s over the mixture of the channels' densities.
    #[inline]
    pub fn scattered_at(&self, d: &Distance, p: Vec3) -> Color {
        let Kind::Homogeneous { sigma_t } = self.kind else { return Color::ZERO };
        let tr = exp_neg(sigma_t, d.t);
        let pdf = (d.q * sigma_t * tr).element_sum();
        let sigma_s = sigma_t * self.albedo.eval(p);
        if pdf > 0.0 {
            tr * sigma_s / pdf
        } else {
            Color::ZERO
        }
    }

    /// The weight of reaching a surface at `t`, closer than the drawn
    /// distance: transmittance over the chance of flying that far.
    #[inline]
    pub fn passed(&self, d: &Distance, t: f32) -> Color {
        let Kind::Homogeneous { sigma_t } = self.kind else { return Color::ONE };
        let tr = exp_neg(sigma_t, t);
        let p = (d.q * tr).element_sum();
        if p > 0.0 {
            tr / p
        } else {
            Color::ZERO
        }
    }

    /// The transmittance along `ray` over [0, `t_max`]: exact for a
    /// homogeneous medium, a ratio-tracking estimate (unbiased, each
    /// factor in [0, 1]) for a heterogeneous one.
    #[inline]
    pub fn transmittance(&self, ray: &Ray, t_max: f32, rng: &mut Rng) -> Color {
        match self.kind {
            Kind::Homogeneous { sigma_t } => exp_neg(sigma_t, t_max),
            Kind::Heterogeneous { majorant, bbox } => self.ratio_tracking(majorant, bbox, ray, t_max, rng, |_, _| ()),
        }
    }

    /// Ratio tracking (Novák et al. 2014) through a heterogeneous medium's
    /// box over [0, `t_max`] of `ray`: each factor in [0, 1], `step` told
    /// every tentative collision's distance and the transmittance up to it.
    #[inline]
    fn ratio_tracking(
        &self,
        majorant: f32,
        bbox: Aabb,
        ray: &Ray,
        t_max: f32,
        rng: &mut Rng,
        mut step: impl FnMut(f32, Color),
    ) -> Color {
        let Some((t0, t1)) = bbox.clip(ray, t_max) else { return Color::ONE };
        let mut tr = Color::ONE;
        self.tentative_collisions(majorant, ray, t0, t1, rng, |t, mu, _| {
            let sigma_t = self.sigma_t.eval(ray.at(t)) * self.scale;
            tr *= (Color::ONE - sigma_t / mu).max(Color::ZERO);
            step(t, tr);
            if tr == Color::ZERO {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
        tr
    }

    /// The tentative collisions of delta and ratio tracking along `ray`
    /// over [`t0`, `t1`] (inside a heterogeneous medium's box), in order:
    /// a Poisson process of the local majorant's rate, told to `collide`
    /// with that rate until it breaks. One exponential optical depth is
    /// drawn per collision and spent across the majorants' pieces (the
    /// process is memoryless), so a piece without a collision costs no
    /// draw.
    #[inline]
    fn tentative_collisions(
        &self,
        majorant: f32,
        ray: &Ray,
        t0: f32,
        t1: f32,
        rng: &mut Rng,
        mut collide: impl FnMut(f32, f32, &mut Rng) -> ControlFlow<()>,
    ) {
        let mut depth = -(1.0 - rng.random::<f32>()).ln();
        let mut piece = |a: f32, b: f32, mu: f32| {
            if !(mu > 0.0) {
                return ControlFlow::Continue(());
            }
            let mut t = a;
            loop {
                let span = (b - t) * mu;
                if !(depth < span) {
                    depth -= span;
                    return ControlFlow::Continue(());
                }
                t += depth / mu;
                collide(t, mu, rng)?;
                depth = -(1.0 - rng.random::<f32>()).ln();
            }
        };
        match &self.majorants {
            Some(m) => m.walk(ray, t0, t1, piece),
            None => {
                let _ = piece(t0, t1, majorant);
            }
        }
    }
}

/// exp(-σ t) per channel, 1 where σ is 0 whatever t (an infinite segment
/// through a channel that does not attenuate).
#[inline]
fn exp_neg(sigma: Color, t: f32) -> Color {
    let x = |s: f32| if s > 0.0 { (-s * t).exp() } else { 1.0 };
    // A grey medium's channels are one number: one exponential.
    if sigma.x == sigma.y && sigma.y == sigma.z {
        return Color::splat(x(sigma.x));
    }
    Color::new(x(sigma.x), x(sigma.y), x(sigma.z))
}

/// The chances of the three channels, in proportion to the path's weight
/// (equal where it is zero or not finite).
#[inline]
fn channel_weights(throughput: Color) -> Color {
    let w = throughput.abs();
    let sum = w.element_sum();
    if sum > 0.0 && sum.is_finite() {
        w / sum
    } else {
        Color::splat(1.0 / 3.0)
    }
}

fn scatters(albedo: &Volume, sigma_t_max: f32, scale: f32) -> bool {
    albedo.max() > 0.0 && sigma_t_max > 0.0 && scale > 0.0
}

fn check_coefficients(lo: f32, hi: f32, scale: f32, albedo: &Volume) -> Result<(), String> {
    if !(lo >= 0.0 && hi.is_finite()) {
        return Err(format!("sigma_t must be finite and not negative (it ranges over [{lo}, {hi}])"));
    }
    if !(scale >= 0.0 && scale.is_finite()) {
        return Err(format!("scale must be finite and not negative, got {scale}"));
    }
    let (a, b) = (albedo.min(), albedo.max());
    if !(a >= 0.0 && b <= 1.0) {
        return Err(format!("the albedo must lie in [0, 1] (it ranges over [{a}, {b}])"));
    }
    Ok(())
}

/// Which media lie on either side of a shape's surface: inside (against
/// its geometric normal) and outside (`None`: vacuum). A ray crossing the
/// surface of a shape that has an interface enters the medium on the side
/// it leaves towards, whatever medium it was in before; a shape without
/// one changes nothing (Mitsuba 3's `is_medium_transition` and
/// `target_medium`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Interface {
    pub interior: Option<u32>,
    pub exterior: Option<u32>,
}

/// A scene's media, as its front-end describes them.
#[derive(Clone, Debug, Default)]
pub struct MediaParts {
    pub media: Vec<Medium>,
    /// Per primitive of the scene's parts (or shorter: the rest have none).
    pub prims: Vec<Option<Interface>>,
    /// Per light of the scene's parts: the interface of an area light's surface.
    pub lights: Vec<Option<Interface>>,
    /// The medium the camera is in.
    pub camera: Option<u32>,
}

/// A scene's media, placed: what the integrators ask.
#[derive(Clone, Debug)]
pub struct Media {
    pub media: Vec<Medium>,
    /// Per primitive of the scene.
    interfaces: Vec<Option<Interface>>,
    pub camera: Option<u32>,
    /// Per medium, where the lights reach into it: built by the first
    /// camera pass that asks (it needs the whole scene's shadow rays),
    /// kept for the passes after.
    lit: Vec<std::sync::OnceLock<LitGrid>>,
}

impl Media {
    /// `interfaces` per primitive of the scene, in its order.
    pub fn new(media: Vec<Medium>, interfaces: Vec<Option<Interface>>, camera: Option<u32>) -> Self {
        let lit = media.iter().map(|_| std::sync::OnceLock::new()).collect();
        Media { media, interfaces, camera, lit }
    }

    /// Medium `medium`'s grid of where the lights reach, `build` making it
    /// the first time (once: callers meanwhile wait for it).
    pub fn lit_grid(&self, medium: u32, build: impl FnOnce() -> LitGrid) -> &LitGrid {
        self.lit[medium as usize].get_or_init(build)
    }

    /// The medium a ray travelling along `dir` is in after crossing (or
    /// leaving) primitive `prim`, whose geometric normal is `normal`, when
    /// it was in `current` before.
    #[inline]
    pub fn after(&self, current: Option<u32>, prim: u32, normal: Vec3, dir: Vec3) -> Option<u32> {
        match self.interfaces.get(prim as usize).copied().flatten() {
            Some(i) => {
                if dir.dot(normal) > 0.0 {
                    i.exterior
                } else {
                    i.interior
                }
            }
            None => current,
        }
    }

    /// The interface on primitive `prim`, if any.
    pub fn interface(&self, prim: u32) -> Option<Interface> {
        self.interfaces.get(prim as usize).copied().flatten()
    }

    #[inline]
    pub fn get(&self, medium: u32) -> &Medium {
        &self.media[medium as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{stream, Domain};
    use glam::Affine3A;

    fn constant(c: Color) -> Volume {
        Volume::Constant { value: c, to_world: Affine3A::IDENTITY }
    }

    /// A homogeneous slab's transmittance is Beer–Lambert's exactly, and
    /// the chance a flight passes it, weighed, is that too: the mean
    /// weight of flights that pass equals exp(-σ d) per channel, even with
    /// channels of very different σ.
    #[test]
    fn homogeneous_flights_keep_beer_lambert() {
        let sigma = Color::new(0.2, 1.0, 3.0);
        let m = Medium::homogeneous(sigma, constant(Color::splat(0.5)), 2.0, Phase::Isotropic).unwrap();
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        let mut rng = stream(1, Domain::Camera, 0);
        let d = 0.7;
        let exact = Color::new((-0.4f32 * d).exp(), (-2.0f32 * d).exp(), (-6.0f32 * d).exp());
        assert_eq!(m.transmittance(&ray, d, &mut rng), exact);
        let n = 400_000;
        let mut passed = glam::DVec3::ZERO;
        // Scattered weight: what reaches the scattering points, integrated
        // over the slab: ∫ σ_s e^{-σ t} dt = albedo (1 - e^{-σ d}).
        let mut scattered = glam::DVec3::ZERO;
        for _ in 0..n {
            match m.sample_flight(&ray, d, Color::ONE, &mut rng) {
                Flight::Passed { weight } => passed += weight.as_dvec3(),
                Flight::Scattered { t, weight } => {
                    assert!(t >= 0.0 && t < d);
                    scattered += weight.as_dvec3();
                }
            }
        }
        let (passed, scattered) = (passed / n as f64, scattered / n as f64);
        for c in 0..3 {
            let e = exact[c] as f64;
            assert!((passed[c] - e).abs() < 0.01 * e + 2e-3, "channel {c}: {} vs {e}", passed[c]);
            let s = 0.5 * (1.0 - e);
            assert!((scattered[c] - s).abs() < 0.01 * s + 2e-3, "channel {c}: {} vs {s}", scattered[c]);
        }
    }
}
