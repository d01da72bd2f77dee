//! Final gathering's directions towards mirrors, glass and bright spots.
//!
//! Light that reaches a diffuse point through a glass or mirror object (the
//! floor seen through a glass ball, its caustic among it) arrives from the
//! object's small solid angle, often focused into a smaller one still: a
//! cosine-distributed gather ray finds it rarely and then carries a large
//! value, a bright speckle in an otherwise smooth image. A few gather rays
//! are therefore aimed: uniformly in the cone of each mirror or glass
//! object's bounding sphere (the caustic photons' targets), and at points
//! of each flat bright spot's plane drawn from its irradiance there
//! ([`PatchMap`]). Every
//! gather ray, cosine or aimed, is weighed by the balance heuristic (Veach
//! 1997, multi-sample model): f cos / (n_cos p_cos + n_aim p_aim). No light
//! is lost or counted twice, whatever the targets hold.

use crate::math::Frame;
use crate::photon::spots::PatchMap;
use crate::sampling::{cone_to_sphere, uniform_cone, uniform_cone_pdf};
use glam::{Vec2, Vec3};

/// What final gathering aims at.
#[derive(Clone, Copy, Debug)]
pub enum Aim<'a> {
    /// A sphere (centre, radius): directions uniform in its cone.
    Sphere(Vec3, f32),
    /// A flat bright spot (its map, its radius): points of its plane drawn
    /// from its irradiance. A sunlit patch seen from a wall at a grazing
    /// angle fills a few times less of its bounding sphere's cone than of
    /// the directions towards its plane, and of those only the bright ones
    /// carry light.
    Patch(&'a PatchMap, f32),
}

/// One target as seen from the gathering point.
#[derive(Clone, Copy, Debug)]
enum Target<'a> {
    Cone { axis: Vec3, cos_max: f32, pdf: f32 },
    Patch(&'a PatchMap),
}

/// The targets a gathering point can see above its horizon, kept by a
/// thread between points (no allocation per point).
#[derive(Default)]
pub struct AimTargets<'a> {
    x: Vec3,
    targets: Vec<Target<'a>>,
}

impl<'a> AimTargets<'a> {
    /// The targets, from `x` on a surface facing `n`, that reach above its
    /// horizon (judged by their bounding spheres); false where there are
    /// none. A target whose bounding sphere holds `x` (a cone wider than
    /// the hemisphere) is left to the cosine rays: aiming at it would only
    /// repeat them.
    pub fn prepare(&mut self, aims: impl Iterator<Item = Aim<'a>>, x: Vec3, n: Vec3) -> bool {
        self.targets.clear();
        self.x = x;
        for aim in aims {
            let (center, radius) = match aim {
                Aim::Sphere(center, radius) => (center, radius),
                Aim::Patch(map, radius) => (map.center(), radius),
            };
            let (axis, cos_max) = cone_to_sphere(x, center, radius);
            if !(cos_max > 0.0) {
                continue;
            }
            let sin_max = (1.0 - cos_max * cos_max).max(0.0).sqrt();
            if axis.dot(n) <= -sin_max {
                continue;
            }
            self.targets.push(match aim {
                Aim::Sphere(..) => Target::Cone { axis, cos_max, pdf: uniform_cone_pdf(cos_max) },
                Aim::Patch(map, _) => Target::Patch(map),
            });
        }
        !self.targets.is_empty()
    }

    /// A direction towards one target, chosen by `pick` in [0, 1).
    pub fn sample(&self, pick: f32, u: Vec2) -> Vec3 {
        let i = ((pick * self.targets.len() as f32) as usize).min(self.targets.len() - 1);
        match self.targets[i] {
            Target::Cone { axis, cos_max, .. } => {
                Frame::from_normal(axis).to_world(uniform_cone(u, cos_max)).normalize()
            }
            Target::Patch(map) => (map.sample(u) - self.x).normalize_or(map.normal()),
        }
    }

    /// The pdf of [`Self::sample`] per unit solid angle towards `dir`:
    /// the mixture over the targets that hold it.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let sum: f32 = self.targets.iter().map(|t| t.pdf(self.x, dir)).sum();
        sum / self.targets.len() as f32
    }
}

impl Target<'_> {
    /// The pdf per unit solid angle of a direction uniform in the cone, or
    /// towards a point of the patch's plane (its area pdf there, times
    /// distance^2 / cos).
    fn pdf(&self, x: Vec3, dir: Vec3) -> f32 {
        match *self {
            Target::Cone { axis, cos_max, pdf } => {
                if dir.dot(axis) >= cos_max {
                    pdf
                } else {
                    0.0
                }
            }
            Target::Patch(map) => {
                let cos = dir.dot(map.normal());
                let t = (map.center() - x).dot(map.normal()) / cos;
                if !(t > 0.0) || !t.is_finite() {
                    return 0.0;
                }
                let pdf = map.area_pdf(x + t * dir) * t * t / cos.abs();
                if pdf.is_finite() {
                    pdf
                } else {
                    0.0
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, uniform_cone, Domain};
    use rand::RngExt;

    /// A flat spot's map, slanted: bright on a band across it, dim
    /// elsewhere.
    fn patch() -> PatchMap {
        let (center, normal) = (Vec3::new(0.8, 0.3, 2.0), Vec3::new(0.3, 0.2, -1.0).normalize());
        PatchMap::build(center, normal, 0.9, |x| if (x - center).x.abs() < 0.2 { 50.0 } else { 0.5 }).unwrap()
    }

    fn spheres(patch: &PatchMap) -> Vec<Aim<'_>> {
        vec![
            Aim::Sphere(Vec3::new(0.0, 0.0, 2.0), 0.5),
            Aim::Sphere(Vec3::new(0.4, 0.0, 2.5), 0.7),
            // A slanted patch, overlapping the second sphere's cone.
            Aim::Patch(patch, 0.9),
            // Below the horizon: never aimed at.
            Aim::Sphere(Vec3::new(0.0, 0.0, -3.0), 1.0),
            // Holding the point: left to the cosine rays.
            Aim::Sphere(Vec3::new(0.1, 0.0, 0.0), 1.0),
        ]
    }

    #[test]
    fn only_targets_above_the_horizon_and_not_around_the_point_are_aimed_at() {
        let patch = patch();
        let mut targets = AimTargets::default();
        assert!(targets.prepare(spheres(&patch).into_iter(), Vec3::ZERO, Vec3::Z));
        assert_eq!(targets.targets.len(), 3);
        assert!(!targets.prepare(spheres(&patch).into_iter().skip(3), Vec3::ZERO, Vec3::Z));
        // A cone that grazes the horizon from below still counts.
        let grazing = [Aim::Sphere(Vec3::new(2.0, 0.0, -0.1), 0.5)];
        assert!(targets.prepare(grazing.into_iter(), Vec3::ZERO, Vec3::Z));
    }

    /// The pdf integrates to one over the sphere, and samples land where it
    /// is positive: a Monte Carlo estimate of 1 from uniform directions.
    #[test]
    fn the_mixture_pdf_is_a_density_of_the_samples() {
        let patch = patch();
        let mut targets = AimTargets::default();
        targets.prepare(spheres(&patch).into_iter(), Vec3::ZERO, Vec3::Z);
        let mut rng = stream(7, Domain::Camera, 0);
        let n = 1_000_000;
        let integral: f64 = (0..n).map(|_| targets.pdf(uniform_cone(next_2d(&mut rng), -1.0)) as f64).sum::<f64>()
            * 4.0
            * std::f64::consts::PI
            / n as f64;
        assert!((integral - 1.0).abs() < 0.02, "{integral}");
        for _ in 0..10_000 {
            let d = targets.sample(rng.random(), next_2d(&mut rng));
            assert!(targets.pdf(d) > 0.0, "{d}");
            assert!((d.length() - 1.0).abs() < 1e-5);
        }
    }
}
