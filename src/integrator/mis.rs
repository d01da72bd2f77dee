//! Multiple importance sampling of direct light (Veach 1997, ch. 9) at
//! vertices with a glossy lobe.
//!
//! There, light arriving straight from the lights is found two ways: by
//! shadow rays to samples of each light ([`super::direct_light_mis`]) and
//! by the direction the BSDF draws for the path's continuation, when it
//! meets a light. A narrow lobe under a large light (or the sky) is found
//! well only by the second, a small light under a wide lobe only by the
//! first; each estimate is weighted by the power heuristic over both, so
//! the weights of a direction sum to one and light reaching the vertex is
//! counted once.
//!
//! The power heuristic (exponent 2) rather than the balance heuristic:
//! where one strategy's density is far above the other's (the usual case
//! here: a highlight seen by a lobe much narrower or much wider than its
//! light), it gives that strategy nearly all of the weight, and Veach
//! (§9.2.4, fig. 9.8) measured it below the balance heuristic's variance
//! in exactly these low-variance regions, never far above it elsewhere.

use crate::math::Color;
use crate::scene::{Hit, Scene};
use glam::Vec3;

/// The power heuristic's weight (exponent 2) of a sample from strategy f,
/// of which `nf` samples were taken with density `pf`, against strategy
/// g's `ng` with density `pg`. One where g cannot draw the direction.
#[inline]
pub fn power_heuristic(nf: f32, pf: f32, ng: f32, pg: f32) -> f32 {
    let (f, g) = (nf * pf, ng * pg);
    if !(g > 0.0) {
        return 1.0;
    }
    let (f2, g2) = (f * f, g * g);
    let w = f2 / (f2 + g2);
    // Densities so large their squares overflow: compare the ratio.
    if w.is_finite() {
        w
    } else {
        1.0 / (1.0 + (g / f).powi(2))
    }
}

/// A direction the BSDF drew at a vertex that took shadow rays with MIS:
/// what the light met along it needs for its weight.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The vertex and the normal its shadow rays were sampled about.
    pub point: Vec3,
    pub normal: Vec3,
    /// The density per solid angle with which the direction was drawn.
    pub pdf: f32,
    /// Shadow rays per (non-delta) light at the vertex.
    pub shadow_rays: u32,
    /// Whether they were drawn by `Source::sample_li_shared`
    /// ([`super::direct_light_shared`]).
    pub compensated: bool,
}

impl BsdfSample {
    /// Weight of light from the scene's light `index` arriving along the
    /// sample, whose own sampling density towards it is `pdf_light`.
    #[inline]
    fn weight(&self, scene: &Scene, index: usize, pdf_light: f32) -> f32 {
        power_heuristic(1.0, self.pdf, scene.light_share(index, self.shadow_rays, self.point, self.normal), pdf_light)
    }

    /// Radiance leaving the area light whose surface the sample met at
    /// `hit` (travelling along `dir`), weighted; zero for any other surface.
    #[inline(never)]
    pub fn emitted(&self, scene: &Scene, hit: &Hit, dir: Vec3) -> Color {
        let (Some(area), Some(index)) = (scene.light_of(hit.prim), scene.light_index_of(hit.prim)) else {
            return Color::ZERO;
        };
        let le = scene.emitted(hit, dir);
        if le == Color::ZERO {
            return Color::ZERO;
        }
        le * self.weight(scene, index, area.pdf_at(self.point, hit.point))
    }

    /// Light from everywhere arriving along `dir` (the sample met
    /// nothing), each light at infinity weighted by its own density.
    #[inline(never)]
    pub fn from_infinity(&self, scene: &Scene, dir: Vec3) -> Color {
        let mut sum = Color::ZERO;
        for &index in scene.lights_at_infinity() {
            let index = index as usize;
            let light = &scene.lights[index];
            let le = light.radiance_from_infinity(dir);
            if le != Color::ZERO {
                let pdf = if self.compensated {
                    light.pdf_li_shared(self.point, self.normal, dir)
                } else {
                    light.pdf_li(self.point, self.normal, dir)
                };
                sum += le * self.weight(scene, index, pdf);
            }
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two strategies' weights of one direction sum to one.
    #[test]
    fn weights_of_a_direction_sum_to_one() {
        for (pf, pg) in [(1.0, 1.0), (0.3, 20.0), (1e30, 1e-3), (4.0, 0.0), (0.0, 5.0), (1e25, 3e25)] {
            for n in [1.0, 4.0, 16.0] {
                let sum = power_heuristic(n, pf, 1.0, pg) + power_heuristic(1.0, pg, n, pf);
                let both = pf > 0.0 && pg > 0.0;
                assert!(!both || (sum - 1.0).abs() < 1e-6, "{pf} {pg} {n}: {sum}");
            }
        }
        assert_eq!(power_heuristic(1.0, 2.0, 1.0, 0.0), 1.0);
        assert!((power_heuristic(1.0, 1.0, 1.0, 3.0) - 0.1).abs() < 1e-7);
    }
}
