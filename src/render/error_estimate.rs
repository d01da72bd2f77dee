//! How wrong a progressive image still is, from its passes alone.
//!
//! The passes are independent, and pass i's expected value is
//! L + B·s_i: the true radiance L plus a bias that shrinks with the pass's
//! shrink factor s_i (its squared radius caps and k; a density estimate's
//! bias is proportional to its squared radius, to first order). Per pixel
//! and channel a least-squares line through the passes' values against
//! s_i, pass 0 left out, gives
//! * the noise of the average: the residuals' variance over N, with pass
//!   0's distance from the other passes' mean counted as that pass's
//!   share. Pass 0's estimates are the widest, and
//!   off the line: fitted with it, a blurred first pass, or one rare
//!   bright photon in it, read as a steep slope, and the suite's bias
//!   predictions came out 2-10 times the error measured;
//! * its bias, B·s̄ (s̄ the mean shrink factor of the passes included), with
//!   the slope's own sampling variance, so that B̂²s̄² minus that variance
//!   estimates the squared bias without the noise's contribution; a
//!   region counts it only where its sum stands out of its own noise.
//!
//! Per pixel the bias estimate is far noisier than the bias (its variance
//! is about ten times the average's noise variance at any pass count);
//! summed over thousands of pixels the noise cancels, so a region's
//! predicted MSE is what to read, and what notes/error-estimates.md
//! calibrates against references. Path tracing has no bias: its passes'
//! spread alone is its error.

use crate::film::accumulation::{Accumulation, PassSet};
use crate::film::Film;
use crate::math::Color;
use crate::metrics::Window;

/// How a render's passes are biased.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BiasModel {
    /// Unbiased passes (path tracing).
    None,
    /// Bias proportional to the pass's shrink factor s_i =
    /// prod_{k=1}^{i} (k + alpha - 1) / k (progressive photon mapping).
    Shrinking { alpha: f32 },
}

/// Σs and Σs² over a set of passes.
fn shrink_sums(passes: &PassSet, alpha: f32) -> (f64, f64) {
    let (mut s, mut sum, mut sum2) = (1.0f64, 0.0, 0.0);
    let mut next = passes.iter().peekable();
    for i in 0..passes.end() {
        if i > 0 {
            s *= (i as f64 + alpha as f64 - 1.0) / i as f64;
        }
        if next.peek() == Some(&i) {
            next.next();
            sum += s;
            sum2 += s * s;
        }
    }
    (sum, sum2)
}

/// Per pixel and channel: the variance of the average's noise, the bias
/// estimate, and that estimate's sampling variance.
#[derive(Clone, Debug)]
pub struct ErrorEstimate {
    pub width: u32,
    pub height: u32,
    pub passes: u32,
    pub noise_var: Vec<[f64; 3]>,
    pub bias: Vec<[f64; 3]>,
    pub bias_var: Vec<[f64; 3]>,
    /// The average image's values.
    pub mean: Vec<[f64; 3]>,
    /// Passes the bias line was fitted to (0: no line).
    pub line_passes: u32,
}

/// Pass 0's noise is read from its distance to the line at s = 1 where
/// the line's variance there is at most this many noise variances.
const MAX_FIRST_LEVERAGE: f64 = 5.0;

/// A region's bias counts from this many passes in the line (three
/// residual degrees of freedom) ...
const MIN_LINE_PASSES_FOR_BIAS: u32 = 5;
/// ... and where the pixels' squared-bias estimates add up to more than
/// this many standard errors of their sum. Per pixel they are far noisier
/// than the bias; a region's sum is noise unless it stands out of it. On
/// the suite, counting every region's sum put the prediction at 2-17 times
/// the measured error in scenes of rare bright paths (the knot, the sun
/// window at 4-16 passes) with no bias measured there.
const BIAS_SIGNIFICANCE: f64 = 3.0;

/// A region's predicted error.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Prediction {
    /// Predicted RMSE over the region's pixels and channels (noise and bias).
    pub rmse: f64,
    pub noise_rmse: f64,
    pub bias_rmse: f64,
    /// Predicted relMSE (the metric's: squared error over r² + 0.01).
    pub relmse: f64,
    /// The region's mean radiance.
    pub mean: f64,
}

impl Prediction {
    /// RMSE relative to the region's mean (what `--target-error` reads).
    pub fn relative_rmse(&self) -> f64 {
        if self.mean > 0.0 {
            self.rmse / self.mean
        } else {
            0.0
        }
    }
}

impl ErrorEstimate {
    /// The estimate from an accumulation of passes; `None` with too few
    /// passes to tell noise from bias (four for photon mapping from pass 0,
    /// three for other sets of passes, two for path tracing).
    pub fn new(acc: &Accumulation, model: BiasModel) -> Option<ErrorEstimate> {
        let n = acc.passes.count();
        let nf = n as f64;
        let alpha = match model {
            BiasModel::None => {
                return (n >= 2).then(|| Self::unbiased(acc));
            }
            BiasModel::Shrinking { alpha } => alpha,
        };
        // The line is fitted to the passes after the first, whose widest
        // estimates lie off it: on the suite, a first pass's blur (or one
        // rare bright photon in it, where the line's slope reads it as
        // bias) made the bias 2-10 times what was measured. The first
        // pass's distance from the line at s = 1 counts as its noise; from
        // the others' mean while the line, extrapolated to s = 1 from a few
        // close shrink factors, is too uncertain there (its variance over
        // five noise variances, about the first eight passes: the knot's
        // prediction at 4 passes was 3x the error measured).
        let skip_first = acc.passes.iter().next() == Some(0);
        let (mut s, mut s2) = shrink_sums(&acc.passes, alpha);
        let s_all = s / nf;
        if skip_first {
            s -= 1.0;
            s2 -= 1.0;
        }
        let m = if skip_first { n - 1 } else { n };
        let mf = m as f64;
        let sss = s2 - s * s / mf;
        // Passes with (nearly) the same shrink factor cannot tell the
        // bias's slope, and a line needs a residual to measure noise.
        if m < 3 || !(sss > 1e-9 * s2) {
            return None;
        }
        let s_mean = s / mf;
        let leverage = 1.0 / mf + (1.0 - s_mean).powi(2) / sss;
        let by_line = leverage <= MAX_FIRST_LEVERAGE;
        let mut est = Self::empty(acc);
        est.line_passes = m;
        for (i, sums) in acc.pixels.iter().enumerate() {
            let [x, xx, sx, first] = sums.to_f64();
            for c in 0..3 {
                est.mean[i][c] = x[c] / nf;
                let (x, xx, sx) = match skip_first {
                    true => (x[c] - first[c], xx[c] - first[c] * first[c], sx[c] - first[c]),
                    false => (x[c], xx[c], sx[c]),
                };
                let ss_xx = (xx - x * x / mf).max(0.0);
                let sxs = sx - s * x / mf;
                let slope = sxs / sss;
                let var = (ss_xx - slope * sxs).max(0.0) / (mf - 2.0);
                est.noise_var[i][c] = match skip_first {
                    true => {
                        let (off, off_var) = match by_line {
                            true => (first[c] - (x / mf + slope * (1.0 - s_mean)), var * leverage),
                            false => (first[c] - x / mf, var / mf),
                        };
                        (var * (nf - 1.0) + off * off - off_var) / (nf * nf)
                    }
                    false => var / nf,
                };
                est.bias[i][c] = slope * s_all;
                est.bias_var[i][c] = var * s_all * s_all / sss;
            }
        }
        Some(est)
    }

    /// Passes without bias: their spread over their count.
    fn unbiased(acc: &Accumulation) -> ErrorEstimate {
        let nf = acc.passes.count() as f64;
        let mut est = Self::empty(acc);
        for (i, sums) in acc.pixels.iter().enumerate() {
            let [x, xx, _, _] = sums.to_f64();
            for c in 0..3 {
                est.mean[i][c] = x[c] / nf;
                est.noise_var[i][c] = (xx[c] - x[c] * x[c] / nf).max(0.0) / (nf - 1.0) / nf;
            }
        }
        est
    }

    fn empty(acc: &Accumulation) -> ErrorEstimate {
        let len = acc.pixels.len();
        ErrorEstimate {
            width: acc.width,
            height: acc.height,
            passes: acc.passes.count(),
            noise_var: vec![[0.0; 3]; len],
            bias: vec![[0.0; 3]; len],
            bias_var: vec![[0.0; 3]; len],
            mean: vec![[0.0; 3]; len],
            line_passes: 0,
        }
    }

    /// The predicted error of the pixels in `window` (all when `None`).
    pub fn predict(&self, window: Option<&Window>) -> Prediction {
        let (mut noise, mut bias2, mut bias2_sq, mut mean, mut count) = (0.0, 0.0, 0.0, 0.0, 0u64);
        // relMSE weighs dark pixels most, where a few passes' noisy
        // estimates of a pixel's noise (pass 0's term can be negative)
        // would decide its sign: its noise part counts each pixel's at
        // least zero.
        let (mut rel_noise, mut rel_bias) = (0.0, 0.0);
        for row in 0..self.height {
            for col in 0..self.width {
                if window.is_some_and(|w| !w.contains(row, col)) {
                    continue;
                }
                let i = (row * self.width + col) as usize;
                for c in 0..3 {
                    // b̂² overstates b² by the estimate's own variance.
                    let b2 = self.bias[i][c] * self.bias[i][c] - self.bias_var[i][c];
                    noise += self.noise_var[i][c];
                    bias2 += b2;
                    bias2_sq += b2 * b2;
                    let m = self.mean[i][c];
                    rel_noise += self.noise_var[i][c].max(0.0) / (m * m + 1e-2);
                    rel_bias += b2 / (m * m + 1e-2);
                    mean += m;
                    count += 1;
                }
            }
        }
        let n = count.max(1) as f64;
        // The standard error of the sum of the pixels' squared-bias terms.
        let spread = (bias2_sq - bias2 * bias2 / n).max(0.0).sqrt();
        let counts = self.line_passes >= MIN_LINE_PASSES_FOR_BIAS && bias2 > BIAS_SIGNIFICANCE * spread;
        let (bias2, rel_bias) = if counts { (bias2 / n, rel_bias / n) } else { (0.0, 0.0) };
        let noise = (noise / n).max(0.0);
        Prediction {
            rmse: (noise + bias2).sqrt(),
            noise_rmse: noise.sqrt(),
            bias_rmse: bias2.sqrt(),
            relmse: rel_noise / n + rel_bias,
            mean: mean / n,
        }
    }

    /// Per pixel: the standard error of the average's noise.
    pub fn noise_film(&self) -> Film {
        self.film(|i, c| self.noise_var[i][c].max(0.0).sqrt())
    }

    /// Per pixel: the bias estimate (signed; noisy, see the module docs).
    pub fn bias_film(&self) -> Film {
        self.film(|i, c| self.bias[i][c])
    }

    /// Per pixel: the predicted RMS error, noise and the bias estimate less
    /// its own variance (at least the noise).
    pub fn error_film(&self) -> Film {
        self.film(|i, c| {
            let b2 = self.bias[i][c] * self.bias[i][c] - self.bias_var[i][c];
            (self.noise_var[i][c] + b2.max(0.0)).max(0.0).sqrt()
        })
    }

    fn film(&self, f: impl Fn(usize, usize) -> f64) -> Film {
        let pixels = (0..self.mean.len())
            .map(|i| {
                let v = |c| {
                    let v = f(i, c) as f32;
                    if v.is_finite() {
                        v
                    } else {
                        0.0
                    }
                };
                Color::new(v(0), v(1), v(2))
            })
            .collect();
        Film { width: self.width, height: self.height, pixels }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, Domain};

    /// Synthetic passes x_i = L + B·s_i + noise, with known L, B and noise:
    /// the region's prediction recovers the noise and the bias of the
    /// average.
    #[test]
    fn recovers_known_noise_and_bias() {
        let (w, h, n, alpha) = (64u32, 64u32, 24u32, 2.0f32 / 3.0);
        let (l, b, sigma) = (0.5f64, 0.2f64, 0.05f64);
        let mut acc = Accumulation::new(w, h);
        let mut s = 1.0f64;
        let mut rng = stream(9, Domain::Camera, 0);
        for i in 0..n {
            if i > 0 {
                s *= (i as f64 + alpha as f64 - 1.0) / i as f64;
            }
            let pixels = (0..w * h)
                .map(|_| {
                    // Uniform noise with standard deviation sigma.
                    let mut v = || (l + b * s + sigma * 12f64.sqrt() * (next_2d(&mut rng).x as f64 - 0.5)) as f32;
                    Color::new(v(), v(), v())
                })
                .collect();
            acc.add_pass(i, &Film { width: w, height: h, pixels }, s).unwrap();
        }
        let est = ErrorEstimate::new(&acc, BiasModel::Shrinking { alpha }).unwrap();
        let (s_sum, _) = shrink_sums(&acc.passes, alpha);
        let true_bias = b * s_sum / n as f64;
        let p = est.predict(None);
        let true_noise = sigma / (n as f64).sqrt();
        assert!((p.noise_rmse / true_noise - 1.0).abs() < 0.03, "noise {} vs {true_noise}", p.noise_rmse);
        assert!((p.bias_rmse / true_bias - 1.0).abs() < 0.05, "bias {} vs {true_bias}", p.bias_rmse);
        // Without bias the bias part vanishes (to its noise).
        let unbiased = ErrorEstimate::new(&acc, BiasModel::None).unwrap();
        assert_eq!(unbiased.predict(None).bias_rmse, 0.0);
    }

    #[test]
    fn too_few_passes_give_no_estimate() {
        let mut acc = Accumulation::new(2, 2);
        let film = Film::new(2, 2);
        acc.add_pass(0, &film, 1.0).unwrap();
        acc.add_pass(1, &film, 0.6).unwrap();
        assert!(ErrorEstimate::new(&acc, BiasModel::Shrinking { alpha: 0.6 }).is_none());
        assert!(ErrorEstimate::new(&acc, BiasModel::None).is_some());
    }

    #[test]
    fn shrink_sums_follow_the_schedule() {
        let set = PassSet::parse("0..2,3..4").unwrap();
        let (s, s2) = shrink_sums(&set, 0.5);
        let s_i = [1.0, 0.5, 0.5 * 1.5 / 2.0, 0.5 * 0.75 * 2.5 / 3.0];
        assert!((s - (s_i[0] + s_i[1] + s_i[3])).abs() < 1e-12);
        assert!((s2 - (1.0 + 0.25 + s_i[3] * s_i[3])).abs() < 1e-12);
    }
}
