//! What the photon-mapping camera pass asks of a medium along one camera
//! segment: the transmittance from the segment's start to every point of
//! it (which the beam radiance estimate weighs each photon by), and
//! distances along it at which single scattering is estimated by shadow
//! rays.

use super::{exp_neg, Kind, Medium};
use crate::math::{Color, Ray};
use glam::Vec2;
use rand::RngExt;

/// A segment's transmittance as a function of distance: exact in a
/// homogeneous medium; in a heterogeneous one, ratio tracking's running
/// product (Novák et al. 2014), which at every distance is an unbiased
/// estimate of the transmittance up to it.
#[derive(Debug, Default)]
pub struct Steps {
    /// (distance, transmittance from 0 to just past it), increasing.
    steps: Vec<(f32, Color)>,
}

impl Medium {
    /// Tracks the transmittance along `ray` over [0, `t_max`] into
    /// `steps` (a heterogeneous medium's; a homogeneous one needs none),
    /// returning the transmittance over the whole segment.
    pub fn track(&self, ray: &Ray, t_max: f32, rng: &mut crate::sampling::Rng, steps: &mut Steps) -> Color {
        steps.steps.clear();
        match self.kind {
            Kind::Homogeneous { sigma_t } => exp_neg(sigma_t, t_max),
            Kind::Heterogeneous { majorant, bbox } => {
                let Some((t0, t1)) = bbox.clip(ray, t_max) else { return Color::ONE };
                if !(majorant > 0.0) {
                    return Color::ONE;
                }
                let mut tr = Color::ONE;
                let mut t = t0;
                loop {
                    t -= (1.0 - rng.random::<f32>()).ln() / majorant;
                    if !(t < t1) {
                        return tr;
                    }
                    let sigma_t = self.sigma_t.eval(ray.at(t)) * self.scale;
                    tr *= (Color::ONE - sigma_t / majorant).max(Color::ZERO);
                    steps.steps.push((t, tr));
                    if tr == Color::ZERO {
                        return tr;
                    }
                }
            }
        }
    }

    /// The transmittance from the segment's start to distance `t`, from
    /// what [`Self::track`] left in `steps`.
    #[inline]
    pub fn transmittance_to(&self, steps: &Steps, t: f32) -> Color {
        match self.kind {
            Kind::Homogeneous { sigma_t } => exp_neg(sigma_t, t),
            Kind::Heterogeneous { .. } => match steps.steps.partition_point(|s| s.0 <= t) {
                0 => Color::ONE,
                i => steps.steps[i - 1].1,
            },
        }
    }

    /// A distance along `ray` within [0, `t_max`] where the medium has
    /// density, drawn in proportion to exp(-σ t) truncated to the segment
    /// (σ each channel's extinction, chosen uniformly, in a homogeneous
    /// medium; the majorant inside a heterogeneous one's box), with its
    /// density; `None` where the segment holds no density.
    pub fn sample_along(&self, ray: &Ray, t_max: f32, u: Vec2) -> Option<(f32, f32)> {
        let (sigma, t0, t1) = match self.kind {
            Kind::Homogeneous { sigma_t } => (sigma_t, 0.0, t_max),
            Kind::Heterogeneous { majorant, bbox } => {
                let (t0, t1) = bbox.clip(ray, t_max)?;
                (Color::splat(majorant), t0, t1)
            }
        };
        let len = t1 - t0;
        // Channels with density share the draws equally.
        let mut live = [0.0f32; 3];
        let mut count = 0;
        for s in sigma.to_array() {
            if s > 0.0 {
                live[count] = s;
                count += 1;
            }
        }
        let live = &live[..count];
        if live.is_empty() || !(len > 0.0) {
            return None;
        }
        let q = 1.0 / live.len() as f32;
        let c = ((u.x * live.len() as f32) as usize).min(live.len() - 1);
        let truncated = |s: f32| -(-s * len).exp_m1();
        let draw = |s: f32, u: f32| {
            if s * len < 1e-4 {
                u * len
            } else {
                -(-u * truncated(s)).ln_1p() / s
            }
        };
        let t = draw(live[c], u.y).clamp(0.0, len);
        if !t.is_finite() {
            return None;
        }
        let pdf: f32 =
            live.iter().map(|&s| if s * len < 1e-4 { q / len } else { q * s * (-s * t).exp() / truncated(s) }).sum();
        (pdf > 0.0 && pdf.is_finite()).then_some((t0 + t, pdf))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::medium::{Phase, Volume};
    use crate::sampling::{stream, Domain};
    use glam::{Affine3A, Vec3};

    /// The distances drawn along a segment integrate a function by their
    /// density: ∫₀^L exp(-t) dt estimated with a homogeneous medium's
    /// draws (channels of very different σ) within 0.5%.
    #[test]
    fn distances_along_a_segment_integrate_by_their_density() {
        let albedo = Volume::Constant { value: Color::ONE, to_world: Affine3A::IDENTITY };
        let m = Medium::homogeneous(Color::new(0.1, 1.0, 8.0), albedo, 1.0, Phase::Isotropic).unwrap();
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        let mut rng = stream(3, Domain::Camera, 0);
        let len = 2.0f32;
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let (t, pdf) = m.sample_along(&ray, len, crate::sampling::next_2d(&mut rng)).unwrap();
            assert!((0.0..=len).contains(&t));
            sum += ((-t).exp() / pdf) as f64;
        }
        let want = 1.0 - (-len as f64).exp();
        assert!((sum / n as f64 - want).abs() < 0.005 * want, "{} vs {want}", sum / n as f64);
    }
}
