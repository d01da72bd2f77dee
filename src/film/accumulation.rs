//! The running sums of a progressive render's passes. They are kept in
//! fixed point (integers in units of 2^-64), because integer addition
//! does not depend on its order: passes rendered in one process, or in
//! any number of processes and added in any order, give the same bits.
//! Floating-point sums would differ in their last bits with the grouping.
//!
//! Besides each pixel's sum, the sums the error estimate needs
//! ([`super::error_estimate`]): of the squares, of the values weighted by
//! the pass's shrink factor (how far its estimates have narrowed), and the
//! first pass's value on its own (its widest estimates are the one pass
//! the error estimate's line leaves out).

use crate::film::Film;
use crate::math::Color;
use std::fmt;
use std::ops::Range;

/// One unit of the fixed-point sums is 2^-64: far below an f32's resolution
/// at any radiance a pixel takes, with room for sums up to ~9.2e18.
const SCALE: f64 = 18_446_744_073_709_551_616.0;

fn fixed(v: f64) -> i128 {
    // `as` saturates (and takes NaN to 0): a sum cannot wrap around.
    (v * SCALE).round() as i128
}

fn float(v: i128) -> f64 {
    v as f64 / SCALE
}

/// A pixel's sums over the passes included, per channel: of its values x,
/// of x², and of s·x with s the pass's shrink factor; and pass 0's value
/// x₀ (zero when pass 0 is not included).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelSums {
    pub x: [i128; 3],
    pub xx: [i128; 3],
    pub sx: [i128; 3],
    pub first: [i128; 3],
}

/// The words a pixel's sums take in a file: 12 sums of 4 words.
pub const WORDS: usize = 48;

impl PixelSums {
    fn add(&mut self, c: Color, shrink: f64, first: bool) {
        for (i, v) in c.to_array().into_iter().enumerate() {
            let v = v as f64;
            self.x[i] = self.x[i].saturating_add(fixed(v));
            self.xx[i] = self.xx[i].saturating_add(fixed(v * v));
            self.sx[i] = self.sx[i].saturating_add(fixed(shrink * v));
            if first {
                self.first[i] = fixed(v);
            }
        }
    }

    fn merge(&mut self, o: &PixelSums) {
        for i in 0..3 {
            self.x[i] = self.x[i].saturating_add(o.x[i]);
            self.xx[i] = self.xx[i].saturating_add(o.xx[i]);
            self.sx[i] = self.sx[i].saturating_add(o.sx[i]);
            // At most one of the two holds pass 0: the other's is zero.
            self.first[i] = self.first[i].saturating_add(o.first[i]);
        }
    }

    /// The sums as floating point: (Σx, Σx², Σs·x, x₀) per channel.
    pub fn to_f64(&self) -> [[f64; 3]; 4] {
        [self.x.map(float), self.xx.map(float), self.sx.map(float), self.first.map(float)]
    }

    /// The twelve sums as 48 little-endian 32-bit words (x, xx, sx, first;
    /// R, G, B; lowest word first), for files.
    pub fn words(&self) -> [u32; WORDS] {
        let mut out = [0u32; WORDS];
        for (k, v) in self.x.iter().chain(&self.xx).chain(&self.sx).chain(&self.first).enumerate() {
            let bits = *v as u128;
            for w in 0..4 {
                out[4 * k + w] = (bits >> (32 * w)) as u32;
            }
        }
        out
    }

    pub fn from_words(words: &[u32; WORDS]) -> PixelSums {
        let v =
            |k: usize| -> i128 { (0..4).fold(0u128, |acc, w| acc | (words[4 * k + w] as u128) << (32 * w)) as i128 };
        PixelSums { x: [v(0), v(1), v(2)], xx: [v(3), v(4), v(5)], sx: [v(6), v(7), v(8)], first: [v(9), v(10), v(11)] }
    }
}

/// A set of pass indices, as sorted, disjoint, non-adjacent ranges.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PassSet(Vec<Range<u32>>);

impl PassSet {
    pub fn ranges(&self) -> &[Range<u32>] {
        &self.0
    }

    pub fn count(&self) -> u32 {
        self.0.iter().map(|r| r.end - r.start).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    pub fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        self.0.iter().flat_map(|r| r.clone())
    }

    /// The first pass after the last one included (0 when empty).
    pub fn end(&self) -> u32 {
        self.0.last().map_or(0, |r| r.end)
    }

    /// Whether the set is 0..n for some n (no pass missing).
    pub fn is_prefix(&self) -> bool {
        self.0.len() <= 1 && self.0.first().is_none_or(|r| r.start == 0)
    }

    /// Adds `range`; refuses (changing nothing) if it shares a pass with
    /// the set.
    pub fn insert(&mut self, range: Range<u32>) -> Result<(), Range<u32>> {
        if range.is_empty() {
            return Ok(());
        }
        if let Some(r) = self.0.iter().find(|r| r.start < range.end && range.start < r.end) {
            return Err(r.start.max(range.start)..r.end.min(range.end));
        }
        let at = self.0.partition_point(|r| r.start < range.start);
        self.0.insert(at, range);
        // Join neighbours that touch.
        let mut joined: Vec<Range<u32>> = Vec::with_capacity(self.0.len());
        for r in self.0.drain(..) {
            match joined.last_mut() {
                Some(last) if last.end == r.start => last.end = r.end,
                _ => joined.push(r),
            }
        }
        self.0 = joined;
        Ok(())
    }

    /// Parses "0..4,8..12" (and "3" for 3..4).
    pub fn parse(text: &str) -> Result<PassSet, String> {
        let mut set = PassSet::default();
        for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let range = parse_range(part)?;
            set.insert(range.clone()).map_err(|o| format!("'{text}': passes {o:?} are given twice"))?;
        }
        Ok(set)
    }
}

/// "A..B" (B > A) or a single pass "A".
pub fn parse_range(text: &str) -> Result<Range<u32>, String> {
    let num = |s: &str| s.trim().parse::<u32>().map_err(|_| format!("'{text}': '{s}' is not a pass number"));
    let range = match text.split_once("..") {
        Some((a, b)) => num(a)?..num(b)?,
        None => {
            let a = num(text)?;
            a..a.checked_add(1).ok_or_else(|| format!("'{text}': pass number too large"))?
        }
    };
    if range.is_empty() {
        return Err(format!("'{text}': a pass range A..B needs B > A"));
    }
    Ok(range)
}

impl fmt::Display for PassSet {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let parts: Vec<String> = self.0.iter().map(|r| format!("{}..{}", r.start, r.end)).collect();
        write!(f, "{}", parts.join(","))
    }
}

/// The exact sums of a set of passes' images.
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulation {
    pub width: u32,
    pub height: u32,
    pub passes: PassSet,
    pub pixels: Vec<PixelSums>,
}

impl Accumulation {
    pub fn new(width: u32, height: u32) -> Self {
        Accumulation {
            width,
            height,
            passes: PassSet::default(),
            pixels: vec![PixelSums::default(); width as usize * height as usize],
        }
    }

    /// Adds pass `pass`'s image; `shrink` is its estimates' shrink factor
    /// (0 for estimators without one). Refuses a pass already included.
    pub fn add_pass(&mut self, pass: u32, film: &Film, shrink: f64) -> Result<(), Range<u32>> {
        assert_eq!((film.width, film.height), (self.width, self.height));
        self.passes.insert(pass..pass + 1)?;
        for (sums, c) in self.pixels.iter_mut().zip(&film.pixels) {
            sums.add(*c, shrink, pass == 0);
        }
        Ok(())
    }

    /// Adds another accumulation of the same image size; refuses (changing
    /// nothing) one that shares a pass with this one, returning those passes.
    pub fn merge(&mut self, other: &Accumulation) -> Result<(), Range<u32>> {
        assert_eq!((other.width, other.height), (self.width, self.height));
        let mut passes = self.passes.clone();
        for r in other.passes.ranges() {
            passes.insert(r.clone())?;
        }
        self.passes = passes;
        for (a, b) in self.pixels.iter_mut().zip(&other.pixels) {
            a.merge(b);
        }
        Ok(())
    }

    /// The average of the passes: the image.
    pub fn average(&self) -> Film {
        let n = self.passes.count().max(1) as f64;
        let pixels = self
            .pixels
            .iter()
            .map(|s| {
                let [x, y, z] = s.x.map(|v| (float(v) / n) as f32);
                Color::new(x, y, z)
            })
            .collect();
        Film { width: self.width, height: self.height, pixels }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(seed: u32, w: u32, h: u32) -> Film {
        // Values over many orders of magnitude, where float sums would
        // depend on their grouping.
        let pixels = (0..w * h)
            .map(|i| {
                let k = (i.wrapping_mul(2_654_435_761) ^ seed.wrapping_mul(40_503)) as f32 / u32::MAX as f32;
                Color::new(k * 1e3, (k * 7.0).fract() * 1e-3, (k * 13.0).fract())
            })
            .collect();
        Film { width: w, height: h, pixels }
    }

    /// Passes added one by one and passes merged in groups, in any order,
    /// give the same bits.
    #[test]
    fn sums_do_not_depend_on_grouping_or_order() {
        let films: Vec<Film> = (0..12).map(|i| film(i, 7, 5)).collect();
        // The passes' shrink factors, computed once (powi's last bit may
        // differ between call sites).
        let shrink: Vec<f64> = (0..12).map(|i| crate::render::photon_stage::shrink(0.7, i)).collect();
        let mut one = Accumulation::new(7, 5);
        for (i, f) in films.iter().enumerate() {
            one.add_pass(i as u32, f, shrink[i]).unwrap();
        }
        for split in [vec![0..1, 1..12], vec![0..4, 4..8, 8..12], vec![10..12, 0..2, 6..10, 2..6]] {
            let mut merged = Accumulation::new(7, 5);
            for r in split.iter().rev() {
                let mut part = Accumulation::new(7, 5);
                for i in r.clone() {
                    part.add_pass(i, &films[i as usize], shrink[i as usize]).unwrap();
                }
                merged.merge(&part).unwrap();
            }
            assert_eq!(merged, one);
            assert_eq!(merged.average(), one.average());
        }
        assert_eq!(one.passes.to_string(), "0..12");
    }

    #[test]
    fn overlapping_passes_are_refused() {
        let f = film(1, 2, 2);
        let mut a = Accumulation::new(2, 2);
        a.add_pass(3, &f, 1.0).unwrap();
        assert_eq!(a.add_pass(3, &f, 1.0), Err(3..4));
        let mut b = Accumulation::new(2, 2);
        b.add_pass(5, &f, 1.0).unwrap();
        b.add_pass(3, &f, 1.0).unwrap();
        let before = a.clone();
        assert_eq!(a.merge(&b), Err(3..4));
        assert_eq!(a, before);
    }

    #[test]
    fn words_round_trip() {
        let mut s = PixelSums::default();
        s.add(Color::new(1e6, 3.5e-12, 0.25), 0.7, true);
        s.add(Color::new(2.0, 0.0, 1e9), 0.5, false);
        assert_eq!(PixelSums::from_words(&s.words()), s);
        assert!((s.to_f64()[0][0] - 1_000_002.0).abs() < 1e-9);
        assert_eq!(s.to_f64()[3][2], 0.25);
    }

    #[test]
    fn pass_sets() {
        let s = PassSet::parse("8..12, 0..4,4..6").unwrap();
        assert_eq!(s.to_string(), "0..6,8..12");
        assert_eq!(s.count(), 10);
        assert!(!s.is_prefix());
        assert_eq!(s.end(), 12);
        assert!(PassSet::parse("0..4,3..5").is_err());
        assert!(parse_range("4..4").is_err());
        assert!(parse_range("x..4").is_err());
        assert_eq!(parse_range("7"), Ok(7..8));
        assert!(PassSet::parse("0..3").unwrap().is_prefix());
    }
}
