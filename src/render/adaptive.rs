//! Adaptive camera samples for progressive renders: pass 0 traces one
//! pilot sample per pixel besides its own, whose squared difference from
//! the pixel's estimate measures the pixel's within-pixel variance; from
//! it every later pass gives each pixel the same number of samples, more
//! where the samples disagree (notes/progressive.md).
//!
//! Unbiased: a pass's count in a pixel depends on pass 0 only, never on
//! the samples of the pass itself, and each pass's value is still the mean
//! of its samples, so its expectation is what it was. Every pass after
//! pass 0 has the same counts, so the error estimate's model (equal noise
//! across those passes, pass 0's share counted apart) still holds. The
//! pilot is a function of pass 0's photons and random streams alone: a
//! process that renders a range of passes not starting at 0 renders pass 0
//! first for its pilot, and gets the counts one process would.

use super::rims::Rims;
use std::sync::Arc;

/// The pass index whose random streams the pilot samples take: no pass of
/// a render reaches it (`camera_pass::sample_index` keeps 24 bits for the
/// pass).
pub(crate) const PILOT_PASS: u64 = (1 << 24) - 1;

/// The half-width of the square over which the pilot's per-pixel
/// differences are averaged: one squared difference is a variance estimate
/// with one degree of freedom, 25 of them are usable.
const RADIUS: usize = 2;

/// No pixel takes more than this many times the pass's samples: past it a
/// pixel's noise is small against the rest of the image's, and the pilot's
/// estimate of its variance is not trusted further.
const MOST_PER_SPP: u32 = 16;

/// The predicted error² × time must fall at least this much against even
/// samples for the counts to change at all: where the pilot finds even
/// noise, the render stays as it was.
const MIN_GAIN: f64 = 0.03;

/// How a render's camera passes place their samples among the pixels.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Samples {
    /// Every pixel the pass's samples (a classic render, or adaptive
    /// sampling off).
    #[default]
    Even,
    /// Adaptive, not measured yet: the next pass (pass 0) traces the
    /// pilot and fixes the counts.
    Pilot,
    /// The counts of every pass after pass 0, per pixel.
    Fixed(Arc<Vec<u32>>),
}

/// What a render's passes share besides the scene and the settings, found
/// by the first pass that needs it: the rims of the lights' images and the
/// camera samples' counts.
#[derive(Clone, Debug, Default)]
pub struct Guide {
    pub rims: Option<Rims>,
    pub samples: Samples,
}

impl Guide {
    /// A progressive render's guide: adaptive samples or even ones.
    pub fn progressive(adaptive: bool) -> Guide {
        Guide { rims: None, samples: if adaptive { Samples::Pilot } else { Samples::Even } }
    }

    /// Whether the counts are still to be measured.
    pub fn needs_pilot(&self) -> bool {
        self.samples == Samples::Pilot
    }
}

/// Each pixel's samples in the passes after pass 0, from the pilot's
/// squared differences `diff` (per pixel, the mean over the channels of
/// (estimate − pilot sample)², the estimate the mean of `spp` samples) and
/// the rays its pilot sample cast `rays`, of a `width` × `height` film.
///
/// The rule: a pixel's variance per sample v is its squared differences
/// averaged over the (2·RADIUS+1)² square about it, over (1 + 1/spp), its
/// standard deviation σ = √v; its cost c a sample is the rays of the pilot
/// samples averaged over the same square, plus one. Minimising the
/// passes' camera variance Σ v/n at a given time Σ n·c gives
/// n ∝ σ/√c; with at least `spp` a pixel and at most `MOST_PER_SPP` times
/// that, n = clamp(round(spp · σ/√c / t), spp, MOST_PER_SPP · spp), and
/// the threshold t is the one (of the values of σ/√c from their median
/// up, 64 quantiles) that minimises the predicted (Σ v/n) · (Σ n·c), the
/// camera pass's error² × time. Unless that beats even samples by
/// `MIN_GAIN`, every pixel keeps `spp`. Integers from the pilot alone, in
/// pixel order: the same on any number of threads.
pub fn allocate(diff: &[f32], rays: &[f32], width: usize, height: usize, spp: u32) -> Vec<u32> {
    let spp = spp.max(1);
    let even = vec![spp; diff.len()];
    if diff.is_empty() || diff.len() != width * height || rays.len() != diff.len() {
        return even;
    }
    let scale = 1.0 / (1.0 + 1.0 / spp as f64);
    let var: Vec<f64> = box_mean(diff, width, height, RADIUS).into_iter().map(|v| (v * scale).max(0.0)).collect();
    let cost: Vec<f64> = box_mean(rays, width, height, RADIUS).into_iter().map(|r| r.max(0.0) + 1.0).collect();
    let worth: Vec<f64> = var.iter().zip(&cost).map(|(v, c)| (v / c).sqrt()).collect();
    let total_var: f64 = var.iter().sum();
    if !(total_var > 0.0 && total_var.is_finite()) {
        return even;
    }
    let most = spp.saturating_mul(MOST_PER_SPP);
    let count = |w: f64, t: f64| -> u32 { ((w * spp as f64 / t).round().min(most as f64) as u32).max(spp) };
    let predicted = |t: Option<f64>| -> f64 {
        let (mut e, mut time) = (0.0, 0.0);
        for ((&v, &c), &w) in var.iter().zip(&cost).zip(&worth) {
            let k = t.map_or(spp, |t| count(w, t)) as f64;
            e += v / k;
            time += k * c;
        }
        e * time
    };
    let base = predicted(None);
    let mut sorted = worth.clone();
    sorted.sort_by(f64::total_cmp);
    let mut best = (base, None);
    for q in 0..64 {
        let at = 0.5 + 0.5 * q as f64 / 64.0;
        let t = sorted[((at * sorted.len() as f64) as usize).min(sorted.len() - 1)];
        if t <= 0.0 {
            continue;
        }
        let p = predicted(Some(t));
        if p < best.0 {
            best = (p, Some(t));
        }
    }
    match best {
        (p, Some(t)) if p < base * (1.0 - MIN_GAIN) => worth.iter().map(|&w| count(w, t)).collect(),
        _ => even,
    }
}

/// The mean of `values` over the square of half-width `r` about each pixel
/// (clipped at the film's borders), by running sums along rows then
/// columns.
fn box_mean(values: &[f32], width: usize, height: usize, r: usize) -> Vec<f64> {
    let mut rows = vec![0.0f64; values.len()];
    for y in 0..height {
        let row = &values[y * width..(y + 1) * width];
        let mut prefix = vec![0.0f64; width + 1];
        for x in 0..width {
            prefix[x + 1] = prefix[x] + row[x] as f64;
        }
        for x in 0..width {
            let (a, b) = (x.saturating_sub(r), (x + r + 1).min(width));
            rows[y * width + x] = (prefix[b] - prefix[a]) / (b - a) as f64;
        }
    }
    let mut out = vec![0.0f64; values.len()];
    for x in 0..width {
        let mut prefix = vec![0.0f64; height + 1];
        for y in 0..height {
            prefix[y + 1] = prefix[y] + rows[y * width + x];
        }
        for y in 0..height {
            let (a, b) = (y.saturating_sub(r), (y + r + 1).min(height));
            out[y * width + x] = (prefix[b] - prefix[a]) / (b - a) as f64;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Even noise keeps even samples; a noisy patch takes more, in
    /// proportion to its standard deviation, none fewer than the pass's.
    #[test]
    fn samples_go_where_the_pilot_disagrees() {
        let (w, h) = (40, 40);
        // Squared differences of unit-variance noise (exactly 2 on average
        // at 1 spp) with a deterministic wobble.
        let flat: Vec<f32> = (0..w * h).map(|i| 2.0 * (1.0 + 0.3 * ((i * 7919 % 13) as f32 / 13.0 - 0.5))).collect();
        let rays = vec![10.0; w * h];
        assert_eq!(allocate(&flat, &rays, w, h, 1), vec![1; w * h]);
        assert_eq!(allocate(&flat, &rays, w, h, 4), vec![4; w * h]);
        let mut patch = flat.clone();
        for y in 10..20 {
            for x in 10..20 {
                patch[y * w + x] *= 100.0;
            }
        }
        let n = allocate(&patch, &rays, w, h, 1);
        assert!(n.iter().all(|&k| (1..=MOST_PER_SPP).contains(&k)));
        let (inside, outside) = (n[15 * w + 15], n[35 * w + 35]);
        assert_eq!(outside, 1);
        assert!(inside >= 5, "{inside}");
        // No variance at all, or a film of another size: even.
        assert_eq!(allocate(&vec![0.0; w * h], &rays, w, h, 2), vec![2; w * h]);
        assert_eq!(allocate(&patch, &rays, w, h + 1, 2), vec![2; w * h]);
        // The same patch where its samples cost 100 times as much: the
        // allocation goes by σ/√c, which is then even, so nothing changes.
        let mut dear = rays.clone();
        for y in 8..22 {
            for x in 8..22 {
                dear[y * w + x] = 1100.0;
            }
        }
        let m = allocate(&patch, &dear, w, h, 1);
        assert!(m[15 * w + 15] < inside, "{} against {inside}", m[15 * w + 15]);
    }

    #[test]
    fn box_mean_averages_the_clipped_square() {
        let v: Vec<f32> = (0..12).map(|i| i as f32).collect();
        let m = box_mean(&v, 4, 3, 1);
        // Corner (0,0): values 0,1,4,5.
        assert_eq!(m[0], 2.5);
        // Centre (1,1): 0,1,2,4,5,6,8,9,10.
        assert_eq!(m[5], 5.0);
    }
}
