//! What the photon-mapping camera pass asks of a medium along one camera
//! segment: the transmittance from the segment's start to every point of
//! it (which the beam radiance estimate weighs each photon by), and
//! distances along it at which single scattering is estimated by shadow
//! rays.

use super::{exp_neg, Kind, Medium};
use crate::math::{Color, Ray};
use glam::Vec2;

/// A segment's transmittance as a function of distance: exact in a
/// homogeneous medium; in a heterogeneous one, ratio tracking's running
/// product (Novák et al. 2014), which at every distance is an unbiased
/// estimate of the transmittance up to it.
#[derive(Debug, Default)]
pub struct Steps {
    /// (distance, transmittance from 0 to just past it), increasing.
    steps: Vec<(f32, Color)>,
    /// A homogeneous medium's transmittance at evenly spaced distances
    /// `spacing` apart (empty: computed exactly), read by linear interpolation: the beam
    /// estimate asks it at each of hundreds of photons per segment, where
    /// three exponentials each were most of its arithmetic. (Between
    /// entries exp(-σ t) is off its chord by at most (σ Δt)² / 8 of its
    /// value: below 2·10⁻⁴ with σ Δt ≤ 1/25.)
    table: Vec<Color>,
    spacing: f32,
}

/// The most intervals of a homogeneous medium's transmittance table.
const MAX_TABLE: usize = 1024;

impl Medium {
    /// Tracks the transmittance along `ray` over [0, `t_max`] into
    /// `steps` (a heterogeneous medium's; a homogeneous one needs none),
    /// returning the transmittance over the whole segment.
    pub fn track(&self, ray: &Ray, t_max: f32, rng: &mut crate::sampling::Rng, steps: &mut Steps) -> Color {
        steps.steps.clear();
        match self.kind {
            Kind::Homogeneous { sigma_t } => {
                // The table reaches where the transmittance is below e⁻¹⁰
                // in every channel, or the segment's end; beyond, it is
                // computed.
                let sigma_min = sigma_t.min_element();
                let reach = if sigma_min > 0.0 { t_max.min(10.0 / sigma_min) } else { t_max };
                // Entries σ Δt ≤ 1/25 apart, each the one before times
                // the step's transmittance (rounding grows by one ulp an
                // entry, at most 1024 of them).
                steps.table.clear();
                let n = (sigma_t.max_element() * reach / 0.04).ceil();
                if reach.is_finite() && reach > 0.0 && n <= MAX_TABLE as f32 {
                    let n = (n as usize).max(1);
                    steps.spacing = reach / n as f32;
                    let step = exp_neg(sigma_t, steps.spacing);
                    let mut tr = Color::ONE;
                    steps.table.push(tr);
                    for _ in 0..n {
                        tr *= step;
                        steps.table.push(tr);
                    }
                }
                exp_neg(sigma_t, t_max)
            }
            Kind::Heterogeneous { majorant, bbox } => {
                self.ratio_tracking(majorant, bbox, ray, t_max, rng, |t, tr| steps.steps.push((t, tr)))
            }
        }
    }

    /// The transmittance from the segment's start to distance `t`, from
    /// what [`Self::track`] left in `steps`.
    #[inline]
    pub fn transmittance_to(&self, steps: &Steps, t: f32) -> Color {
        match self.kind {
            Kind::Homogeneous { sigma_t } => {
                if steps.table.is_empty() {
                    return exp_neg(sigma_t, t);
                }
                let last = steps.table.len() - 1;
                let x = (t / steps.spacing).max(0.0);
                if !(x < last as f32) {
                    return exp_neg(sigma_t, t);
                }
                let i = (x as usize).min(last - 1);
                let f = x - i as f32;
                steps.table[i] + (steps.table[i + 1] - steps.table[i]) * f
            }
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

    /// The transmittance read from a homogeneous segment's table is
    /// Beer–Lambert's within 0.05%, short
    /// segments and long, grey and chromatic.
    #[test]
    fn a_tracked_homogeneous_segment_reads_beer_lambert() {
        let albedo = Volume::Constant { value: Color::ONE, to_world: Affine3A::IDENTITY };
        let mut rng = stream(5, Domain::Camera, 0);
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        for sigma in [Color::splat(0.25), Color::new(0.05, 1.0, 4.0)] {
            let m = Medium::homogeneous(sigma, albedo.clone(), 1.0, Phase::Isotropic).unwrap();
            for t_max in [0.01f32, 1.0, 7.0, 40.0, f32::INFINITY] {
                let mut steps = Steps::default();
                m.track(&ray, t_max, &mut rng, &mut steps);
                for i in 0..=1000 {
                    let t = i as f32 / 1000.0 * t_max.min(60.0);
                    let (got, want) = (m.transmittance_to(&steps, t), exp_neg(sigma, t));
                    for c in 0..3 {
                        let ok = (got[c] - want[c]).abs() <= 5e-4 * want[c];
                        assert!(ok, "σ {sigma}, segment {t_max}, t {t}: {got} vs {want}");
                    }
                }
            }
        }
    }

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
