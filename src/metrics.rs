//! How far a render is from a reference image: the metric of the
//! references' own script (`tools/metrics.py`, after the one shipped with
//! the default scene's references), generalised to any image size, any
//! number of windows, and a count of speckles. Tests, benches, the suite
//! runner and `photonmap compare` all score through here.
//!
//! * The test image is reduced to the reference's size by averaging
//!   `f` x `f` blocks when the reference is an integer factor `f` smaller
//!   (an 800² render against a 200² reference), as the references' script
//!   does; any other size mismatch is refused.
//! * `rmse` = sqrt(mean((x - r)^2)) over pixels and the three channels;
//!   `relmse` = mean((x - r)^2 / (r^2 + 0.01)); means of both images and the
//!   relative bias of the test's (undefined where the reference's mean is
//!   0). Non-finite test values are counted and scored as 0; a reference
//!   holding a non-finite value is refused, with their count and the first
//!   one's place (there is nothing to score against there).
//! * A window is a rectangle of reference pixels scored the same way.
//! * A speckle is a pixel of the full-size test image more than 4x brighter
//!   (mean of its channels) than the median of its 5x5 neighbourhood, and
//!   brighter than that median by more than 5% of the reference's mean, where
//!   the reference has no such pixel at or next to the same place. The floor
//!   keeps the count to pixels a viewer can see (a stray 1e-5 on a black
//!   background is 4x its median of 0).

use crate::film::Film;
use crate::math::Color;
use glam::DVec3;

pub mod erfc;
pub mod mitsuba_test;

/// The default scene's caustic window in 200² pixel coordinates, rows
/// 173..193 and columns 126..157: it frames the glass sphere's caustic on
/// the floor (how it was chosen: tools/metrics.py).
pub const CAUSTIC_WINDOW_200: (u32, u32, u32, u32) = (173, 193, 126, 157);

/// A rectangle of reference pixels, `rows` and `cols` half-open, row 0 at
/// the top.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Window {
    pub name: String,
    pub rows: (u32, u32),
    pub cols: (u32, u32),
}

impl Window {
    /// The default scene's caustic window for a reference `size` pixels
    /// square (a multiple of 200).
    pub fn default_caustic(size: u32) -> Window {
        let s = (size / 200).max(1);
        let (r0, r1, c0, c1) = CAUSTIC_WINDOW_200;
        Window { name: "caustic".into(), rows: (r0 * s, r1 * s), cols: (c0 * s, c1 * s) }
    }

    /// Whether the window lies within an image of `w` x `h` pixels.
    fn fits(&self, w: u32, h: u32) -> Result<(), Mismatch> {
        if self.rows.1 > h || self.cols.1 > w {
            let (r0, r1, c0, c1) = (self.rows.0, self.rows.1, self.cols.0, self.cols.1);
            return Err(Mismatch::Window { name: self.name.clone(), r0, r1, c0, c1, w, h });
        }
        Ok(())
    }

    /// Parses `[NAME=]R0:R1,C0:C1` (half-open rows and columns of the
    /// reference); the name defaults to `window<index>`.
    pub fn parse(text: &str, index: usize) -> Result<Window, String> {
        let (name, spec) = match text.split_once('=') {
            Some((n, s)) if !n.trim().is_empty() => (n.trim().to_string(), s),
            _ => (format!("window{index}"), text),
        };
        let bad = || format!("window '{text}': expected [NAME=]ROW0:ROW1,COL0:COL1, e.g. caustic=173:193,126:157");
        let (rows, cols) = spec.split_once(',').ok_or_else(bad)?;
        let range = |s: &str| -> Result<(u32, u32), String> {
            let (a, b) = s.split_once(':').ok_or_else(bad)?;
            let (a, b) = (a.trim().parse::<u32>().map_err(|_| bad())?, b.trim().parse::<u32>().map_err(|_| bad())?);
            if a >= b {
                return Err(format!("window '{text}': {a}:{b} is empty (the end is exclusive)"));
            }
            Ok((a, b))
        };
        Ok(Window { name, rows: range(rows)?, cols: range(cols)? })
    }

    pub fn contains(&self, row: u32, col: u32) -> bool {
        (self.rows.0..self.rows.1).contains(&row) && (self.cols.0..self.cols.1).contains(&col)
    }
}

/// The scores of one region (the whole image or a window).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    pub rmse: f64,
    pub relmse: f64,
    /// Mean radiance over the region's pixels and channels.
    pub mean_test: f64,
    pub mean_ref: f64,
    /// Reference pixels in the region.
    pub pixels: u64,
}

impl Region {
    /// The test's mean relative to the reference's, minus one (0 where the
    /// reference's mean is 0: see [`Region::relative_bias`]).
    pub fn bias(&self) -> f64 {
        self.relative_bias().unwrap_or(0.0)
    }

    /// The test's mean relative to the reference's, minus one; `None` where
    /// the reference's mean is 0 (or not finite), where no relative figure
    /// means anything.
    pub fn relative_bias(&self) -> Option<f64> {
        (self.mean_ref != 0.0 && self.mean_ref.is_finite()).then(|| self.mean_test / self.mean_ref - 1.0)
    }
}

/// Running sums of one region.
#[derive(Clone, Copy, Default)]
struct Sums {
    d2: f64,
    rel: f64,
    x: f64,
    r: f64,
    pixels: u64,
}

impl Sums {
    fn add(&mut self, x: DVec3, r: DVec3) {
        let d = x - r;
        let d2 = d * d;
        self.d2 += d2.element_sum();
        self.rel += (d2 / (r * r + DVec3::splat(1e-2))).element_sum();
        self.x += x.element_sum();
        self.r += r.element_sum();
        self.pixels += 1;
    }

    fn region(&self) -> Region {
        let n = (3 * self.pixels).max(1) as f64;
        Region {
            rmse: (self.d2 / n).sqrt(),
            relmse: self.rel / n,
            mean_test: self.x / n,
            mean_ref: self.r / n,
            pixels: self.pixels,
        }
    }
}

/// A test image scored against a reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// The reduction applied to the test image (1: none).
    pub factor: u32,
    pub whole: Region,
    pub windows: Vec<(Window, Region)>,
    /// Non-finite values in the test image (scored as 0).
    pub nan_count: u64,
    /// Speckle pixels of the full-size test image (see the module docs).
    pub speckles: u64,
}

/// Why two images cannot be compared.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Mismatch {
    #[error(
        "a {0}x{1} image cannot be compared with a {2}x{3} reference: the test must be the reference's size or an integer multiple of it on both axes"
    )]
    Size(u32, u32, u32, u32),
    #[error("window {name} ({r0}:{r1},{c0}:{c1}) lies outside the {w}x{h} reference")]
    Window { name: String, r0: u32, r1: u32, c0: u32, c1: u32, w: u32, h: u32 },
    #[error(
        "the reference holds {count} non-finite values (NaN or infinite; the first at column {col}, row {row}): a reference must be finite to score against"
    )]
    NonFiniteReference { count: u64, col: u32, row: u32 },
}

/// Refuses a reference holding a non-finite value.
fn finite_reference(reference: &Film) -> Result<(), Mismatch> {
    let mut bad = reference.pixels.iter().enumerate().filter(|(_, c)| !c.is_finite());
    if let Some((first, _)) = bad.next() {
        let count: u64 =
            reference.pixels.iter().map(|c| c.to_array().iter().filter(|v| !v.is_finite()).count() as u64).sum();
        let w = reference.width.max(1);
        return Err(Mismatch::NonFiniteReference { count, col: first as u32 % w, row: first as u32 / w });
    }
    Ok(())
}

/// The integer factor by which `test` is larger than `reference` on both axes.
pub fn reduction_factor(test: (u32, u32), reference: (u32, u32)) -> Result<u32, Mismatch> {
    let mismatch = Mismatch::Size(test.0, test.1, reference.0, reference.1);
    if reference.0 == 0
        || reference.1 == 0
        || !test.0.is_multiple_of(reference.0)
        || !test.1.is_multiple_of(reference.1)
    {
        return Err(mismatch);
    }
    let f = test.0 / reference.0;
    if f == 0 || test.1 / reference.1 != f {
        return Err(mismatch);
    }
    Ok(f)
}

/// Averages `f` x `f` blocks (in f64, as the references' script does).
pub fn box_down(film: &Film, f: u32) -> Film {
    if f == 1 {
        return film.clone();
    }
    let (w, h) = (film.width / f, film.height / f);
    let mut out = Film::new(w, h);
    for r in 0..h {
        for c in 0..w {
            let mut s = DVec3::ZERO;
            for dr in 0..f {
                for dc in 0..f {
                    s += film.get(c * f + dc, r * f + dr).as_dvec3();
                }
            }
            out.pixels[(r * w + c) as usize] = (s / (f * f) as f64).as_vec3();
        }
    }
    out
}

/// The test image with non-finite values replaced by 0, and how many there were.
fn finite(test: &Film) -> (Film, u64) {
    let mut bad = 0;
    let pixels = test
        .pixels
        .iter()
        .map(|c| {
            Color::from_array(c.to_array().map(|v| {
                bad += !v.is_finite() as u64;
                if v.is_finite() {
                    v
                } else {
                    0.0
                }
            }))
        })
        .collect();
    (Film { width: test.width, height: test.height, pixels }, bad)
}

/// Scores `test` against `reference` over the whole image and each window.
pub fn compare_images(test: &Film, reference: &Film, windows: &[Window]) -> Result<Comparison, Mismatch> {
    let factor = reduction_factor((test.width, test.height), (reference.width, reference.height))?;
    for w in windows {
        w.fits(reference.width, reference.height)?;
    }
    finite_reference(reference)?;
    let (clean, nan_count) = finite(test);
    let reduced = box_down(&clean, factor);
    let mut whole = Sums::default();
    let mut in_window = vec![Sums::default(); windows.len()];
    for row in 0..reference.height {
        for col in 0..reference.width {
            let x = reduced.get(col, row).as_dvec3();
            let r = reference.get(col, row).as_dvec3();
            whole.add(x, r);
            for (w, s) in windows.iter().zip(&mut in_window) {
                if w.contains(row, col) {
                    s.add(x, r);
                }
            }
        }
    }
    Ok(Comparison {
        factor,
        whole: whole.region(),
        windows: windows.iter().cloned().zip(in_window.iter().map(Sums::region)).collect(),
        nan_count,
        speckles: speckles(&clean, reference, factor),
    })
}

/// The `window` of `test`, reduced by `factor`, scored against a reference
/// of that window alone (`crop`, its size): where a whole-image reference
/// would be too noisy to measure a small window's error, a crop rendered
/// with many more samples costs a fraction of it.
pub fn compare_window(test: &Film, factor: u32, window: &Window, crop: &Film) -> Result<Region, Mismatch> {
    let (h, w) = (window.rows.1 - window.rows.0, window.cols.1 - window.cols.0);
    if (crop.width, crop.height) != (w, h) {
        return Err(Mismatch::Size(w, h, crop.width, crop.height));
    }
    window.fits(test.width / factor.max(1), test.height / factor.max(1))?;
    finite_reference(crop)?;
    let (clean, _) = finite(test);
    let reduced = box_down(&clean, factor);
    let mut sums = Sums::default();
    for row in 0..h {
        for col in 0..w {
            sums.add(reduced.get(window.cols.0 + col, window.rows.0 + row).as_dvec3(), crop.get(col, row).as_dvec3());
        }
    }
    Ok(sums.region())
}

/// Brightness of a pixel for the speckle count: the mean of its channels.
fn brightness(c: Color) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

/// Which pixels of `film` are speckles by the rule of the module docs, with
/// `floor` the least excess over the neighbourhood's median that counts.
fn speckle_mask(film: &Film, floor: f32) -> Vec<bool> {
    let (w, h) = (film.width as i64, film.height as i64);
    let value: Vec<f32> = film.pixels.iter().map(|&c| brightness(c)).collect();
    let mut mask = vec![false; value.len()];
    let mut near = Vec::with_capacity(25);
    for y in 0..h {
        for x in 0..w {
            let v = value[(y * w + x) as usize];
            if !(v > floor) {
                continue;
            }
            near.clear();
            for dy in -2..=2 {
                for dx in -2..=2 {
                    let (xx, yy) = (x + dx, y + dy);
                    if xx >= 0 && yy >= 0 && xx < w && yy < h {
                        near.push(value[(yy * w + xx) as usize]);
                    }
                }
            }
            let mid = near.len() / 2;
            let median = *near.select_nth_unstable_by(mid, f32::total_cmp).1;
            mask[(y * w + x) as usize] = v > 4.0 * median && v - median > floor;
        }
    }
    mask
}

/// Speckles of the full-size `test` image that the `reference` (`factor`
/// times smaller) does not have at or next to the same place.
pub fn speckles(test: &Film, reference: &Film, factor: u32) -> u64 {
    let floor = 0.05 * reference.mean() as f32;
    let in_test = speckle_mask(test, floor);
    let in_ref = speckle_mask(reference, floor);
    let (rw, rh) = (reference.width as i64, reference.height as i64);
    let ref_has = |rx: i64, ry: i64| {
        (-1..=1).any(|dy| {
            (-1..=1).any(|dx| {
                let (x, y) = (rx + dx, ry + dy);
                x >= 0 && y >= 0 && x < rw && y < rh && in_ref[(y * rw + x) as usize]
            })
        })
    };
    let w = test.width as i64;
    in_test
        .iter()
        .enumerate()
        .filter(|&(i, &s)| {
            let (x, y) = (i as i64 % w, i as i64 / w);
            s && !ref_has(x / factor as i64, y / factor as i64)
        })
        .count() as u64
}

/// A signed false-colour picture of `test - reference` (both the
/// reference's size), 8-bit RGB: black where they agree, red where the test
/// is brighter, blue where it is darker, full intensity at `scale` (the
/// difference of the channel means) and beyond, on a square-root ramp so
/// that small differences stay visible. `scale` `None`: the 99th percentile
/// of the absolute differences. Returns the pixels and the scale used.
pub fn diff_rgb8(test: &Film, reference: &Film, scale: Option<f32>) -> (Vec<u8>, f32) {
    let d: Vec<f32> = test.pixels.iter().zip(&reference.pixels).map(|(&a, &b)| brightness(a) - brightness(b)).collect();
    let scale = scale.unwrap_or_else(|| {
        let mut abs: Vec<f32> = d.iter().map(|v| v.abs()).filter(|v| v.is_finite()).collect();
        if abs.is_empty() {
            return 1.0;
        }
        let k = ((abs.len() as f64 * 0.99) as usize).min(abs.len() - 1);
        *abs.select_nth_unstable_by(k, f32::total_cmp).1
    });
    let scale = if scale > 0.0 && scale.is_finite() { scale } else { 1.0 };
    let px = d
        .iter()
        .flat_map(|&v| {
            let t = (v.abs() / scale).clamp(0.0, 1.0).sqrt();
            let hot = (255.0 * t) as u8;
            // A little of the other channels at full scale, so the
            // strongest differences read as light red or light blue.
            let warm = (255.0 * (t - 0.75).max(0.0) * 2.0) as u8;
            if !v.is_finite() {
                [255, 0, 255]
            } else if v > 0.0 {
                [hot, warm, warm]
            } else {
                [warm, warm, hot]
            }
        })
        .collect();
    (px, scale)
}

/// A heat map of non-negative per-pixel values (an error estimate): black
/// at 0 through red and yellow to white at `scale` (the 99th percentile of
/// the values when `None`) and beyond. Returns the pixels and the scale.
pub fn heat_rgb8(values: &Film, scale: Option<f32>) -> (Vec<u8>, f32) {
    let v: Vec<f32> = values.pixels.iter().map(|&c| brightness(c)).collect();
    let scale = scale.unwrap_or_else(|| {
        let mut finite: Vec<f32> = v.iter().copied().filter(|x| x.is_finite()).collect();
        if finite.is_empty() {
            return 1.0;
        }
        let k = ((finite.len() as f64 * 0.99) as usize).min(finite.len() - 1);
        *finite.select_nth_unstable_by(k, f32::total_cmp).1
    });
    let scale = if scale > 0.0 && scale.is_finite() { scale } else { 1.0 };
    let px = v
        .iter()
        .flat_map(|&x| {
            let t = if x.is_finite() { (x / scale).clamp(0.0, 1.0) } else { 1.0 };
            let ramp = |a: f32| (255.0 * (3.0 * t - a).clamp(0.0, 1.0)) as u8;
            [ramp(0.0), ramp(1.0), ramp(2.0)]
        })
        .collect();
    (px, scale)
}

/// The scores of the default scene's references: whole image and the
/// caustic window (kept as the fields `tools/metrics.py` prints).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    pub rmse: f64,
    pub relmse: f64,
    pub caustic_rmse: f64,
    pub mean_x: f64,
    pub mean_r: f64,
    pub caustic_mean_x: f64,
    pub caustic_mean_r: f64,
    pub nan_count: u64,
}

impl Metrics {
    pub fn from_comparison(c: &Comparison) -> Metrics {
        let caustic = c.windows.first().map_or(c.whole, |w| w.1);
        Metrics {
            rmse: c.whole.rmse,
            relmse: c.whole.relmse,
            caustic_rmse: caustic.rmse,
            mean_x: c.whole.mean_test,
            mean_r: c.whole.mean_ref,
            caustic_mean_x: caustic.mean_test,
            caustic_mean_r: caustic.mean_ref,
            nan_count: c.nan_count,
        }
    }
}

/// Scores a render of the default scene against one of its references (a
/// multiple of 200 pixels square) with the caustic window; `None` when the
/// sizes do not compare.
pub fn compare(test: &Film, reference: &Film) -> Option<Metrics> {
    let window = Window::default_caustic(reference.width);
    let windows =
        if reference.width.is_multiple_of(200) && reference.height == reference.width { vec![window] } else { vec![] };
    compare_images(test, reference, &windows).ok().map(|c| Metrics::from_comparison(&c))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(w: u32, h: u32, f: impl Fn(u32, u32) -> Color) -> Film {
        Film { width: w, height: h, pixels: (0..w * h).map(|i| f(i % w, i / w)).collect() }
    }

    /// A window scored against a crop of the reference scores as the same
    /// window of the whole reference, the test reduced alike; a crop of
    /// another size is refused.
    #[test]
    fn a_window_against_its_crop_scores_as_against_the_whole_reference() {
        let reference = film(10, 8, |x, y| Color::new(0.1 * x as f32, 0.05 * y as f32, 0.3));
        let test = film(20, 16, |x, y| Color::new(0.06 * x as f32, 0.02 * (x + y) as f32, 0.25 + 0.01 * y as f32));
        let w = Window::parse("spot=2:7,3:9", 0).unwrap();
        let whole = compare_images(&test, &reference, std::slice::from_ref(&w)).unwrap();
        let crop = film(6, 5, |x, y| reference.get(x + 3, y + 2));
        let alone = compare_window(&test, whole.factor, &w, &crop).unwrap();
        let full = whole.windows[0].1;
        assert_eq!(alone.pixels, full.pixels);
        assert!((alone.rmse - full.rmse).abs() < 1e-12 && (alone.relmse - full.relmse).abs() < 1e-12);
        assert!((alone.mean_test - full.mean_test).abs() < 1e-12 && (alone.mean_ref - full.mean_ref).abs() < 1e-12);
        assert!(compare_window(&test, whole.factor, &w, &film(5, 6, |_, _| Color::ZERO)).is_err());
        assert!(
            compare_window(&test, 2, &Window::parse("2:9,3:9", 0).unwrap(), &film(6, 7, |_, _| Color::ZERO)).is_err()
        );
    }

    /// A known difference gives the known numbers: a test 0.1 brighter than
    /// a reference of 0.5 everywhere, and 0.3 brighter in a 2x3 window.
    #[test]
    fn a_known_difference_gives_the_known_scores() {
        let reference = film(10, 8, |_, _| Color::splat(0.5));
        let test = film(10, 8, |x, y| Color::splat(if (2..5).contains(&x) && (1..3).contains(&y) { 0.8 } else { 0.6 }));
        let w = Window::parse("spot=1:3,2:5", 0).unwrap();
        let c = compare_images(&test, &reference, &[w.clone(), Window::parse("0:8,0:10", 1).unwrap()]).unwrap();
        assert_eq!(c.factor, 1);
        let (spot, all) = (c.windows[0].1, c.windows[1].1);
        assert_eq!(spot.pixels, 6);
        assert!((spot.rmse - 0.3).abs() < 1e-6, "{spot:?}");
        assert!((spot.bias() - 0.6).abs() < 1e-6);
        assert!((spot.relmse - 0.09 / 0.26).abs() < 1e-6);
        // Whole image: 6 pixels off by 0.3, 74 by 0.1.
        let want = ((6.0 * 0.09 + 74.0 * 0.01) / 80.0f64).sqrt();
        assert!((c.whole.rmse - want).abs() < 1e-6, "{} vs {want}", c.whole.rmse);
        assert_eq!(all, c.whole);
        assert!((c.whole.mean_ref - 0.5).abs() < 1e-9);
        assert_eq!(c.windows[1].0.name, "window1");
    }

    #[test]
    fn a_larger_test_is_box_filtered_and_other_sizes_are_refused() {
        let reference = film(4, 3, |x, y| Color::splat((x + 10 * y) as f32));
        // Each reference pixel's 4x4 block averages to the reference value.
        let test = film(16, 12, |x, y| {
            let v = ((x / 4) + 10 * (y / 4)) as f32;
            Color::splat(v + if (x + y) % 2 == 0 { 1.0 } else { -1.0 })
        });
        let c = compare_images(&test, &reference, &[]).unwrap();
        assert_eq!(c.factor, 4);
        assert!(c.whole.rmse < 1e-6, "{}", c.whole.rmse);
        for (w, h) in [(15, 12), (16, 8), (8, 12), (4, 4), (2, 3)] {
            assert!(compare_images(&film(w, h, |_, _| Color::ZERO), &reference, &[]).is_err(), "{w}x{h}");
        }
        let outside = Window::parse("0:4,0:4", 0).unwrap();
        assert!(matches!(compare_images(&test, &reference, &[outside]), Err(Mismatch::Window { .. })));
    }

    #[test]
    fn windows_parse_and_refuse_nonsense() {
        assert_eq!(Window::parse("caustic=173:193,126:157", 0).unwrap(), Window::default_caustic(200),);
        assert_eq!(Window::parse("1:2,3:4", 7).unwrap().name, "window7");
        for bad in ["1:2", "2:1,0:3", "a:b,1:2", "1:2;3:4", "=1:2,3:4,5"] {
            assert!(Window::parse(bad, 0).is_err(), "{bad}");
        }
    }

    #[test]
    fn non_finite_test_values_are_counted_and_scored_as_zero() {
        let reference = film(2, 1, |_, _| Color::splat(1.0));
        let test = film(2, 1, |x, _| if x == 0 { Color::new(f32::NAN, 1.0, f32::INFINITY) } else { Color::ONE });
        let c = compare_images(&test, &reference, &[]).unwrap();
        assert_eq!(c.nan_count, 2);
        assert!((c.whole.rmse - (2.0f64 / 6.0).sqrt()).abs() < 1e-9);
    }

    /// A NaN or an infinity in the reference is refused with the count of
    /// them and the first one's place (it once made every score NaN while
    /// the count of non-finite values read 0).
    #[test]
    fn a_reference_holding_non_finite_values_is_refused() {
        let test = film(3, 2, |_, _| Color::splat(0.5));
        let mut reference = test.clone();
        reference.pixels[4] = Color::new(f32::NAN, 0.5, f32::INFINITY);
        reference.pixels[5] = Color::new(0.5, f32::NAN, 0.5);
        let e = compare_images(&test, &reference, &[]).unwrap_err();
        assert_eq!(e, Mismatch::NonFiniteReference { count: 3, col: 1, row: 1 });
        assert!(e.to_string().contains("3 non-finite values"), "{e}");
        let w = Window::parse("0:2,0:3", 0).unwrap();
        assert!(matches!(compare_window(&test, 1, &w, &reference), Err(Mismatch::NonFiniteReference { .. })));
    }

    /// Against an all-zero reference the relative bias is undefined, not 0.
    #[test]
    fn the_relative_bias_against_a_black_reference_is_undefined() {
        let reference = film(2, 2, |_, _| Color::ZERO);
        let c = compare_images(&film(2, 2, |_, _| Color::splat(0.25)), &reference, &[]).unwrap();
        assert_eq!(c.whole.relative_bias(), None);
        assert!((c.whole.rmse - 0.25).abs() < 1e-9);
        let c = compare_images(&film(2, 2, |_, _| Color::splat(0.75)), &film(2, 2, |_, _| Color::splat(0.5)), &[]);
        assert!((c.unwrap().whole.relative_bias().unwrap() - 0.5).abs() < 1e-9);
    }

    /// Isolated bright pixels count; a bright region (a light, a caustic)
    /// does not, nor a speckle the reference has too.
    #[test]
    fn speckles_are_isolated_bright_pixels_the_reference_lacks() {
        let reference = film(20, 20, |x, y| if x >= 15 && y >= 15 { Color::splat(5.0) } else { Color::splat(0.2) });
        let mut test = reference.clone();
        let mut set = |x: u32, y: u32, v: f32| test.pixels[(y * 20 + x) as usize] = Color::splat(v);
        set(3, 3, 2.0);
        set(10, 4, 0.9);
        set(7, 12, 0.7); // under 4x the median of 0.2: not a speckle
        let c = compare_images(&test, &reference, &[]).unwrap();
        assert_eq!(c.speckles, 2);
        // The reference has the same speckle: it is not counted.
        let mut reference2 = reference.clone();
        reference2.pixels[3 * 20 + 3] = Color::splat(2.0);
        assert_eq!(compare_images(&test, &reference2, &[]).unwrap().speckles, 1);
        // At full size (a 2x reference), one bright pixel is still one.
        let big = film(40, 40, |x, y| if x == 9 && y == 30 { Color::splat(3.0) } else { reference.get(x / 2, y / 2) });
        assert_eq!(compare_images(&big, &reference, &[]).unwrap().speckles, 1);
    }

    #[test]
    fn the_difference_picture_is_signed() {
        let reference = film(3, 1, |_, _| Color::splat(1.0));
        let test = film(3, 1, |x, _| Color::splat([1.0, 1.5, 0.5][x as usize]));
        let (px, scale) = diff_rgb8(&test, &reference, Some(0.5));
        assert_eq!(scale, 0.5);
        assert_eq!(&px[0..3], &[0, 0, 0]);
        assert!(px[3] == 255 && px[5] < 255, "brighter: red {:?}", &px[3..6]);
        assert!(px[8] == 255 && px[6] < 255, "darker: blue {:?}", &px[6..9]);
    }

    /// The default scene's metric: the caustic window is scaled with the
    /// reference, and compare() reports it.
    #[test]
    fn default_metric_scores_the_caustic_window() {
        assert_eq!(Window::default_caustic(800).rows, (692, 772));
        let reference = film(200, 200, |_, _| Color::splat(1.0));
        let test =
            film(800, 800, |x, y| Color::splat(if Window::default_caustic(800).contains(y, x) { 2.0 } else { 1.0 }));
        let m = compare(&test, &reference).unwrap();
        assert!((m.caustic_rmse - 1.0).abs() < 1e-9 && (m.caustic_mean_x - 2.0).abs() < 1e-9);
        assert!(m.rmse > 0.0 && m.rmse < 0.2);
    }
}
