//! Final gathering's directions towards mirrors, glass and bright spots.
//!
//! Light that reaches a diffuse point through a glass or mirror object (the
//! floor seen through a glass ball, its caustic among it) arrives from the
//! object's small solid angle, often focused into a smaller one still: a
//! cosine-distributed gather ray finds it rarely and then carries a large
//! value, a bright speckle in an otherwise smooth image. A few gather rays
//! are therefore aimed, uniformly in the cone of each mirror or glass
//! object's bounding sphere (the caustic photons' targets), and every gather
//! ray, cosine or aimed, is weighed by the balance heuristic (Veach 1997,
//! multi-sample model): f cos / (n_cos p_cos + n_aim p_aim). No light is
//! lost or counted twice, whatever the cones hold.

use crate::math::Frame;
use crate::sampling::{cone_to_sphere, uniform_cone, uniform_cone_pdf};
use glam::{Vec2, Vec3};

/// One target's cone as seen from the gathering point.
#[derive(Clone, Copy, Debug)]
struct Cone {
    axis: Vec3,
    cos_max: f32,
    pdf: f32,
}

/// The cones of the targets a gathering point can see above its horizon,
/// kept by a thread between points (no allocation per point).
#[derive(Default)]
pub struct AimCones {
    cones: Vec<Cone>,
}

impl AimCones {
    /// The cones, from `x` on a surface facing `n`, of the spheres (centre,
    /// radius) that reach above its horizon; false where there are none. A
    /// sphere that
    /// holds `x` (a cone wider than the hemisphere) is left to the cosine
    /// rays: aiming at it would only repeat them.
    pub fn prepare(&mut self, spheres: impl Iterator<Item = (Vec3, f32)>, x: Vec3, n: Vec3) -> bool {
        self.cones.clear();
        for (center, radius) in spheres {
            let (axis, cos_max) = cone_to_sphere(x, center, radius);
            if !(cos_max > 0.0) {
                continue;
            }
            let sin_max = (1.0 - cos_max * cos_max).max(0.0).sqrt();
            if axis.dot(n) <= -sin_max {
                continue;
            }
            self.cones.push(Cone { axis, cos_max, pdf: uniform_cone_pdf(cos_max) });
        }
        !self.cones.is_empty()
    }

    /// A direction uniform in one cone, chosen by `pick` in [0, 1).
    pub fn sample(&self, pick: f32, u: Vec2) -> Vec3 {
        let i = ((pick * self.cones.len() as f32) as usize).min(self.cones.len() - 1);
        let c = &self.cones[i];
        Frame::from_normal(c.axis).to_world(uniform_cone(u, c.cos_max)).normalize()
    }

    /// The pdf of [`Self::sample`] per unit solid angle towards `dir`:
    /// the mixture over the cones that hold it.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let sum: f32 = self.cones.iter().filter(|c| dir.dot(c.axis) >= c.cos_max).map(|c| c.pdf).sum();
        sum / self.cones.len() as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, uniform_cone, Domain};
    use rand::RngExt;

    fn spheres() -> Vec<(Vec3, f32)> {
        vec![
            (Vec3::new(0.0, 0.0, 2.0), 0.5),
            (Vec3::new(0.4, 0.0, 2.5), 0.7),
            // Below the horizon: never aimed at.
            (Vec3::new(0.0, 0.0, -3.0), 1.0),
            // Holding the point: left to the cosine rays.
            (Vec3::new(0.1, 0.0, 0.0), 1.0),
        ]
    }

    #[test]
    fn only_targets_above_the_horizon_and_not_around_the_point_are_aimed_at() {
        let mut cones = AimCones::default();
        assert!(cones.prepare(spheres().into_iter(), Vec3::ZERO, Vec3::Z));
        assert_eq!(cones.cones.len(), 2);
        assert!(!cones.prepare(spheres().into_iter().skip(2), Vec3::ZERO, Vec3::Z));
        // A cone that grazes the horizon from below still counts.
        let grazing = [(Vec3::new(2.0, 0.0, -0.1), 0.5)];
        assert!(cones.prepare(grazing.into_iter(), Vec3::ZERO, Vec3::Z));
    }

    /// The pdf integrates to one over the sphere, and samples land where it
    /// is positive: a Monte Carlo estimate of 1 from uniform directions.
    #[test]
    fn the_mixture_pdf_is_a_density_of_the_samples() {
        let mut cones = AimCones::default();
        cones.prepare(spheres().into_iter(), Vec3::ZERO, Vec3::Z);
        let mut rng = stream(7, Domain::Camera, 0);
        let n = 400_000;
        let integral: f64 = (0..n).map(|_| cones.pdf(uniform_cone(next_2d(&mut rng), -1.0)) as f64).sum::<f64>()
            * 4.0
            * std::f64::consts::PI
            / n as f64;
        assert!((integral - 1.0).abs() < 0.02, "{integral}");
        for _ in 0..10_000 {
            let d = cones.sample(rng.random(), next_2d(&mut rng));
            assert!(cones.pdf(d) > 0.0, "{d}");
            assert!((d.length() - 1.0).abs() < 1e-5);
        }
    }
}
