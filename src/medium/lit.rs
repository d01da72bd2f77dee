//! Where the lights reach into a medium, on a coarse grid, and distances
//! along a camera segment drawn by it: single scattering's shadow rays
//! spent where there is light to find. In a room lit through a small
//! window (suite scene 12-fog-shafts) a camera segment crosses the shaft
//! of light over a few tenths of its length; drawn by transmittance alone,
//! most of its distances land in the dark, and which of its strata meet
//! the shaft was most of the image's noise (notes/method.md §8).
//!
//! The grid is a sampling density only: the estimate divides by the
//! density it drew from, and every cell keeps a floor (a share of the
//! grid's mean), so a cell the pilot found dark is still drawn and any
//! grid gives the same expectation (defensive importance sampling,
//! Hesterberg 1995).

use super::{Kind, Medium, Steps};
use crate::math::Color;
use crate::math::Ray;
use glam::Vec3;

/// Each cell's floor: this share of the mean over the grid's cells, so a
/// cell found dark is drawn at least at that density against a lit one's.
const FLOOR_SHARE: f32 = 0.5;

/// Light reaching each cell of a box (any measure of it that is high
/// where single scattering is; luminance of the lights' irradiance at
/// points of the cell, without the phase function).
#[derive(Clone, Debug)]
pub struct LitGrid {
    lo: Vec3,
    /// Cells per unit length, per axis.
    inv_cell: Vec3,
    res: [u32; 3],
    /// Per cell (x fastest), the largest of its 27 neighbours' light plus
    /// the floor: a cell cut by the edge of a shaft, which few pilot
    /// points found lit, draws as the shaft's middle does.
    weight: Vec<f32>,
    /// Outside the box: the floor.
    floor: f32,
}

impl LitGrid {
    /// Cells over the box [`lo`, `hi`] of about equal sides, `cells` along
    /// its longest side.
    pub fn resolution(lo: Vec3, hi: Vec3, cells: u32) -> [u32; 3] {
        let ext = (hi - lo).max(Vec3::splat(1e-6));
        let side = ext.max_element() / cells as f32;
        let n = |e: f32| ((e / side).ceil() as u32).clamp(1, cells);
        [n(ext.x), n(ext.y), n(ext.z)]
    }

    /// The centre's offset of cell `i` (x fastest) and its size: where a
    /// pilot places its points.
    pub fn cell_box(lo: Vec3, hi: Vec3, res: [u32; 3], i: usize) -> (Vec3, Vec3) {
        let size = (hi - lo) / Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
        let (x, y, z) = (i as u32 % res[0], i as u32 / res[0] % res[1], i as u32 / (res[0] * res[1]));
        (lo + size * Vec3::new(x as f32, y as f32, z as f32), size)
    }

    /// The grid of `light` (per cell, x fastest; non-finite or negative
    /// values read as none) over [`lo`, `hi`]. Where no cell is lit every
    /// weight is 1: distances drawn by transmittance alone.
    pub fn new(lo: Vec3, hi: Vec3, res: [u32; 3], light: &[f32]) -> LitGrid {
        let [nx, ny, nz] = res.map(|n| n as usize);
        assert_eq!(light.len(), nx * ny * nz, "one value per cell");
        let clean = |v: f32| if v.is_finite() && v > 0.0 { v } else { 0.0 };
        let mut weight = vec![0.0f32; light.len()];
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let mut m = 0.0f32;
                    for cz in z.saturating_sub(1)..(z + 2).min(nz) {
                        for cy in y.saturating_sub(1)..(y + 2).min(ny) {
                            for cx in x.saturating_sub(1)..(x + 2).min(nx) {
                                m = m.max(clean(light[cx + nx * (cy + ny * cz)]));
                            }
                        }
                    }
                    weight[x + nx * (y + ny * z)] = m;
                }
            }
        }
        let mean = weight.iter().map(|&w| w as f64).sum::<f64>() / weight.len() as f64;
        let floor = (FLOOR_SHARE as f64 * mean) as f32;
        if floor > 0.0 && floor.is_finite() {
            for w in &mut weight {
                *w += floor;
            }
        } else {
            weight.iter_mut().for_each(|w| *w = 1.0);
        }
        let floor = if floor > 0.0 && floor.is_finite() { floor } else { 1.0 };
        let inv_cell = Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32) / (hi - lo).max(Vec3::splat(1e-6));
        LitGrid { lo, inv_cell, res, weight, floor }
    }

    /// A grid over the box (-1, -0.5, 0)-(3, 1.5, 2), 8 cells along x, a
    /// tenth of its cells lit at random (stream `seed`): a test's pattern
    /// of shafts.
    #[doc(hidden)]
    pub fn speckled(seed: u64) -> LitGrid {
        use rand::RngExt;
        let (lo, hi) = (Vec3::new(-1.0, -0.5, 0.0), Vec3::new(3.0, 1.5, 2.0));
        let res = LitGrid::resolution(lo, hi, 8);
        let mut rng = crate::sampling::stream(seed, crate::sampling::Domain::Camera, 1);
        let n = (res[0] * res[1] * res[2]) as usize;
        let light: Vec<f32> = (0..n).map(|_| if rng.random::<f32>() < 0.1 { 5.0 } else { 0.0 }).collect();
        LitGrid::new(lo, hi, res, &light)
    }

    /// The pieces of `ray` over [`t0`, `t1`] by cell, as (end, weight),
    /// neighbours of equal weight merged, into `out` (cleared).
    fn pieces(&self, ray: &Ray, t0: f32, t1: f32, out: &mut Vec<(f32, f32)>) {
        out.clear();
        let push = |out: &mut Vec<(f32, f32)>, end: f32, w: f32| match out.last_mut() {
            Some(last) if last.1 == w => last.0 = end,
            _ => out.push((end, w)),
        };
        // The ray in cell units: the grid is the unit-cell box [0, res).
        let o = (ray.origin - self.lo) * self.inv_cell;
        let d = ray.dir * self.inv_cell;
        let res = Vec3::new(self.res[0] as f32, self.res[1] as f32, self.res[2] as f32);
        let inv = d.recip();
        let (a, b) = ((Vec3::ZERO - o) * inv, (res - o) * inv);
        let (near, far) = (a.min(b), a.max(b));
        let enter = near.x.max(near.y).max(near.z).max(t0);
        let leave = far.x.min(far.y).min(far.z).min(t1);
        if !(enter < leave) {
            push(out, t1, self.floor);
            return;
        }
        if enter > t0 {
            push(out, enter, self.floor);
        }
        // Amanatides and Woo's traversal from the cell at the middle of
        // the first step (rounding at the box's faces picks no outside cell).
        let p = o + d * enter;
        let mut cell = [0i64; 3];
        let mut next = [f32::INFINITY; 3];
        let mut delta = [f32::INFINITY; 3];
        let mut step = [0i64; 3];
        for k in 0..3 {
            cell[k] = (p[k].floor() as i64).clamp(0, self.res[k] as i64 - 1);
            if d[k] > 0.0 {
                step[k] = 1;
                delta[k] = inv[k];
                next[k] = enter + ((cell[k] + 1) as f32 - p[k]) * inv[k];
            } else if d[k] < 0.0 {
                step[k] = -1;
                delta[k] = -inv[k];
                next[k] = enter + (cell[k] as f32 - p[k]) * inv[k];
            }
        }
        let limit = self.res.iter().sum::<u32>() + 3;
        for _ in 0..limit {
            let k = if next[0] <= next[1] && next[0] <= next[2] {
                0
            } else if next[1] <= next[2] {
                1
            } else {
                2
            };
            let end = next[k].min(leave);
            let i =
                cell[0] as usize + self.res[0] as usize * (cell[1] as usize + self.res[1] as usize * cell[2] as usize);
            push(out, end, self.weight[i]);
            if end >= leave {
                break;
            }
            cell[k] += step[k];
            if cell[k] < 0 || cell[k] >= self.res[k] as i64 {
                break;
            }
            next[k] += delta[k];
        }
        // Rounding may end the walk short of `leave`: the last piece
        // reaches it.
        if let Some(last) = out.last_mut() {
            last.0 = last.0.max(leave);
        }
        if leave < t1 {
            push(out, t1, self.floor);
        }
    }
}

/// One camera segment's distance density: transmittance (each channel's
/// σ_t drawn with equal chance, the density their mixture: every channel
/// unbiased, as spectral MIS makes a free flight) times the grid's
/// weight, normalised; built once, drawn from several times.
#[derive(Debug, Default)]
pub struct LitSegment {
    /// (end, weight) from `start`.
    pieces: Vec<(f32, f32)>,
    start: f32,
    /// The distinct extinctions drawn from, each with chance 1 / count.
    sigma: [f32; 3],
    count: usize,
    /// Per channel, each piece's mass (cumulative) and the total.
    cdf: [Vec<f32>; 3],
    total: [f32; 3],
    /// Drawn as the tracked transmittance falls (a heterogeneous
    /// medium's): uniform within each piece, whose mass is its weight
    /// times the fall of the channel's transmittance over it.
    tracked: bool,
    /// The lit grid's pieces while the tracked ones are cut from them (kept
    /// between segments: no allocation per segment).
    spare: Vec<(f32, f32)>,
}

/// ∫ₐ^{a+len} e^{-σ (s - a)} ds, stable for small σ len.
fn chord(sigma: f32, len: f32) -> f32 {
    let x = sigma * len;
    if x < 1e-4 {
        len * (1.0 - 0.5 * x)
    } else {
        -(-x).exp_m1() / sigma
    }
}

impl LitSegment {
    /// The density of `ray`'s segment [0, `t_max`] in `medium` with
    /// weights from `grid`; false where the segment has no density to
    /// draw from. Within a heterogeneous medium's box the transmittance is
    /// drawn as a homogeneous medium's of the same optical depth over the
    /// box's part of the segment: `across`, the transmittance over the
    /// whole segment ([`Medium::track`]'s), gives it. (The global
    /// majorant, which it was, falls far faster than the transmittance
    /// through thin smoke: most distances landed near where the segment
    /// enters the box.)
    pub fn build(
        &mut self,
        medium: &Medium,
        grid: &LitGrid,
        ray: &Ray,
        t_max: f32,
        across: crate::math::Color,
        steps: &Steps,
    ) -> bool {
        self.tracked = false;
        let (sigma, t0, t1) = match medium.kind {
            Kind::Homogeneous { sigma_t } => (sigma_t.to_array(), 0.0, t_max),
            Kind::Heterogeneous { bbox, .. } if !steps.steps.is_empty() => {
                let Some((t0, t1)) = bbox.clip(ray, t_max) else { return false };
                if !(t1 > t0) {
                    return false;
                }
                grid.pieces(ray, t0, t1, &mut self.pieces);
                return self.build_tracked(&steps.steps, t0);
            }
            Kind::Heterogeneous { bbox, .. } => {
                let Some((t0, t1)) = bbox.clip(ray, t_max) else { return false };
                // A channel with no extinction at all draws uniformly: a
                // tiny mean keeps it drawable.
                let mean = |tr: f32| if tr > 0.0 { (-tr.ln() / (t1 - t0)).max(1e-6) } else { 1e-6 };
                (across.to_array().map(|tr| if tr > 0.0 && tr.is_finite() { mean(tr) } else { 1e-6 }), t0, t1)
            }
        };
        // (An unbounded segment, a ray leaving the scene in a medium that
        // fills it, ends in a piece of the floor's weight reaching to
        // infinity: its mass e^{-σ a} / σ.)
        if !(t1 > t0) {
            return false;
        }
        self.count = 0;
        for s in sigma {
            if s > 0.0 && !self.sigma[..self.count].contains(&s) {
                self.sigma[self.count] = s;
                self.count += 1;
            }
        }
        if self.count == 0 {
            return false;
        }
        self.start = t0;
        grid.pieces(ray, t0, t1, &mut self.pieces);
        for c in 0..self.count {
            let s = self.sigma[c];
            let cdf = &mut self.cdf[c];
            cdf.clear();
            // e^{-σ (a - start)} at each piece's start, by products.
            let (mut at, mut a, mut sum) = (1.0f32, t0, 0.0f32);
            for &(b, w) in &self.pieces {
                let len = (b - a).max(0.0);
                sum += w * at * chord(s, len);
                cdf.push(sum);
                at *= (-s * len).exp();
                a = b;
            }
            self.total[c] = sum;
        }
        (0..self.count).all(|c| self.total[c] > 0.0 && self.total[c].is_finite())
    }

    /// The density of a heterogeneous segment from its tracked
    /// transmittance (`knots`, from [`Medium::track`], read by linear
    /// interpolation as [`Medium::transmittance_to`] reads them) and the
    /// grid's pieces already in `self.pieces`, from `start`: the pieces cut
    /// at every knot, each drawn in proportion to its weight times the fall
    /// of the transmittance over it, σ_t T integrated, uniformly within it
    /// (where the interpolated transmittance falls at a constant rate).
    /// Drawn as a homogeneous medium's of the same depth, the distances
    /// missed the dense puffs of a smoke and piled into its thin parts,
    /// whose σ_s then weighed them down.
    fn build_tracked(&mut self, knots: &[(f32, Color)], start: f32) -> bool {
        let mut cursor = 0;
        let mut at = |t: f32| super::segment::between_knots_from(knots, &mut cursor, t);
        // Channels whose transmittance falls alike all along are drawn as
        // one (a grey medium's).
        let grey = knots.iter().all(|k| k.1.x == k.1.y && k.1.y == k.1.z);
        let channels: &[usize] = if grey { &[0] } else { &[0, 1, 2] };
        let lit = std::mem::take(&mut self.pieces);
        let mut pieces = std::mem::take(&mut self.spare);
        pieces.clear();
        let (mut a, mut k) = (start, knots.partition_point(|kn| kn.0 <= start));
        for &(end, w) in &lit {
            while a < end {
                let b = if k < knots.len() && knots[k].0 < end { knots[k].0 } else { end };
                if k < knots.len() && knots[k].0 <= b {
                    k += 1;
                }
                if b > a {
                    pieces.push((b, w));
                }
                a = a.max(b);
            }
        }
        self.pieces = pieces;
        self.spare = lit;
        self.start = start;
        self.count = 0;
        for &c in channels {
            let cdf = &mut self.cdf[self.count];
            cdf.clear();
            let (mut before, mut sum) = (1.0f32, 0.0f32);
            for &(b, w) in &self.pieces {
                let after = at(b)[c];
                sum += w * (before - after).max(0.0);
                cdf.push(sum);
                before = after;
            }
            if sum > 0.0 && sum.is_finite() {
                self.total[self.count] = sum;
                self.count += 1;
            }
        }
        self.tracked = true;
        self.count > 0
    }

    /// A distance drawn from the density (`u.x` picks the channel, `u.y`
    /// its place in that channel's distribution: stratify it), with the
    /// density there.
    pub fn sample(&self, u: glam::Vec2) -> Option<(f32, f32)> {
        let c = ((u.x * self.count as f32) as usize).min(self.count - 1);
        if self.tracked {
            let cdf = &self.cdf[c];
            let target = u.y * self.total[c];
            let i = cdf.partition_point(|&m| m <= target).min(cdf.len() - 1);
            let before = if i == 0 { 0.0 } else { cdf[i - 1] };
            let a = if i == 0 { self.start } else { self.pieces[i - 1].0 };
            let b = self.pieces[i].0;
            let mass = cdf[i] - before;
            let r = if mass > 0.0 { ((target - before) / mass).clamp(0.0, 1.0) } else { 0.5 };
            let t = (a + r * (b - a)).clamp(a, b);
            // A distance rounded onto the piece's start is the piece
            // before's, as [`Self::pdf`] reads it.
            let pdf = self.pdf_in(if t > a || i == 0 { i } else { i - 1 }, t);
            return (pdf > 0.0 && pdf.is_finite() && t.is_finite()).then_some((t, pdf));
        }
        let (s, cdf) = (self.sigma[c], &self.cdf[c]);
        let target = u.y * self.total[c];
        let i = cdf.partition_point(|&m| m <= target).min(cdf.len() - 1);
        let before = if i == 0 { 0.0 } else { cdf[i - 1] };
        let a = if i == 0 { self.start } else { self.pieces[i - 1].0 };
        let b = self.pieces[i].0;
        let len = (b - a).max(0.0);
        let mass = cdf[i] - before;
        let r = if mass > 0.0 { ((target - before) / mass).clamp(0.0, 1.0) } else { 0.5 };
        // e^{-σ x} on [0, len], normalised, inverted.
        let x = if s * len < 1e-4 { r * len } else { -(r * (-s * len).exp_m1()).ln_1p() / s };
        let t = (a + x.clamp(0.0, len)).clamp(a, b);
        let pdf = self.pdf_in(i, t);
        (pdf > 0.0 && pdf.is_finite() && t.is_finite()).then_some((t, pdf))
    }

    /// The density at `t` within piece `i`.
    fn pdf_in(&self, i: usize, t: f32) -> f32 {
        let w = self.pieces[i].1;
        let q = 1.0 / self.count as f32;
        if self.tracked {
            let a = if i == 0 { self.start } else { self.pieces[i - 1].0 };
            let len = self.pieces[i].0 - a;
            if !(len > 0.0) {
                return 0.0;
            }
            return (0..self.count)
                .map(|c| {
                    let mass = self.cdf[c][i] - if i == 0 { 0.0 } else { self.cdf[c][i - 1] };
                    q * mass / (self.total[c] * len)
                })
                .sum();
        }
        (0..self.count).map(|c| q * w * (-self.sigma[c] * (t - self.start)).exp() / self.total[c]).sum()
    }

    /// The density at distance `t` (0 outside the segment).
    pub fn pdf(&self, t: f32) -> f32 {
        if !(t >= self.start) {
            return 0.0;
        }
        match self.pieces.iter().position(|&(end, _)| t <= end) {
            Some(i) => self.pdf_in(i, t),
            None => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Color;
    use crate::medium::{Phase, Volume};
    use crate::sampling::{stream, Domain};
    use glam::Affine3A;
    use rand::RngExt;

    fn grid(seed: u64) -> LitGrid {
        LitGrid::speckled(seed)
    }

    /// The pieces cover the segment without gaps, in order, whichever way
    /// the ray crosses the grid or misses it.
    #[test]
    fn pieces_cover_the_segment() {
        let g = grid(1);
        let mut rng = stream(2, Domain::Camera, 0);
        let mut out = Vec::new();
        for _ in 0..2000 {
            let o = Vec3::new(rng.random(), rng.random(), rng.random()) * 6.0 - Vec3::splat(2.0);
            let d = (Vec3::new(rng.random(), rng.random(), rng.random()) - Vec3::splat(0.5)).normalize();
            let t1 = rng.random::<f32>() * 8.0;
            g.pieces(&Ray::new(o, d), 0.0, t1, &mut out);
            assert!(!out.is_empty());
            let mut prev = 0.0;
            for &(end, w) in &out {
                assert!(end >= prev && w > 0.0, "{out:?}");
                prev = end;
            }
            assert_eq!(out.last().unwrap().0, t1, "{out:?}");
        }
    }

    /// Drawn by the grid, the estimate of ∫ e^{-σt} f(t) dt (f a step
    /// along the segment, lit where the grid is dark and dark where it is
    /// lit too) is the integral: the floor keeps it unbiased.
    #[test]
    fn lit_distances_integrate_by_their_density() {
        let albedo = Volume::Constant { value: Color::ONE, to_world: Affine3A::IDENTITY };
        let g = grid(5);
        let m = Medium::homogeneous(Color::splat(0.3), albedo, 1.0, Phase::Isotropic).unwrap();
        let ray = Ray::new(Vec3::new(-1.2, 0.0, 0.4), Vec3::new(1.0, 0.25, 0.3).normalize());
        let t_max = 5.0f32;
        let mut seg = LitSegment::default();
        assert!(seg.build(&m, &g, &ray, t_max, crate::math::Color::ONE, &Steps::default()));
        let f = |t: f32| if (1.0..2.5).contains(&t) || t > 4.0 { 1.0 } else { 0.1 };
        let exact: f64 = {
            let n = 200_000;
            let h = t_max as f64 / n as f64;
            (0..n).map(|i| (i as f64 + 0.5) * h).map(|t| (-0.3 * t).exp() * f(t as f32) as f64 * h).sum()
        };
        let mut rng = stream(4, Domain::Camera, 0);
        let n = 400_000;
        let mut sum = 0.0f64;
        for i in 0..n {
            let u = glam::Vec2::new(rng.random(), (i as f32 + rng.random::<f32>()) / n as f32);
            let (t, pdf) = seg.sample(u).unwrap();
            sum += ((-0.3 * t).exp() * f(t) / pdf) as f64;
        }
        let got = sum / n as f64;
        assert!((got - exact).abs() < 0.002 * exact, "{got} against {exact}");
    }

    /// A smoke: a 6 x 5 x 4 grid of densities 0 to 4 (a quarter of its
    /// cells empty) over the box [-1, 3] x [-0.5, 1.5] x [0, 2], scale 2,
    /// and a ray through it; the segment tracked and its density built.
    fn smoke_segment(seed: u64) -> (Medium, Ray, f32, LitSegment) {
        use crate::medium::vol_file::VolGrid;
        use crate::medium::volume::{Filter, Grid, Wrap};
        let mut rng = stream(seed, Domain::Camera, 3);
        let data = (0..120).map(|_| if rng.random::<f32>() < 0.25 { 0.0 } else { 4.0 * rng.random::<f32>() }).collect();
        let vol = VolGrid { res: [6, 5, 4], channels: 1, bbox: ([0.0; 3], [1.0; 3]), data };
        let place =
            Affine3A::from_translation(Vec3::new(-1.0, -0.5, 0.0)) * Affine3A::from_scale(Vec3::new(4.0, 2.0, 2.0));
        let density = Grid::new(std::sync::Arc::new(vol), place, false, Filter::Trilinear, Wrap::Clamp).unwrap();
        let albedo = Volume::Constant { value: Color::ONE, to_world: Affine3A::IDENTITY };
        let m = Medium::heterogeneous(Volume::Grid(density), albedo, 2.0, Phase::Isotropic).unwrap();
        let ray = Ray::new(Vec3::new(-2.0, 0.1, 0.3), Vec3::new(1.0, 0.15, 0.25).normalize());
        let t_max = 6.0f32;
        let mut steps = Steps::default();
        let across = m.track(&ray, t_max, &mut steps);
        let mut seg = LitSegment::default();
        assert!(seg.build(&m, &grid(seed), &ray, t_max, across, &steps));
        assert!(seg.tracked);
        (m, ray, t_max, seg)
    }

    /// Drawn by the tracked density, single scattering's integral along a
    /// smoke, ∫ σ_t(t) T(t) f(t) dt (f a step, lit where the grid is dark
    /// too), is the integral.
    #[test]
    fn tracked_distances_integrate_by_their_density() {
        let (m, ray, t_max, seg) = smoke_segment(9);
        let f = |t: f32| if (1.0..2.5).contains(&t) || t > 4.0 { 1.0 } else { 0.1 };
        // The medium has density only inside its box (a clamped grid
        // reads its edge beyond).
        let inside = |p: Vec3| p.cmpge(Vec3::new(-1.0, -0.5, 0.0)).all() && p.cmple(Vec3::new(3.0, 1.5, 2.0)).all();
        let sigma = |t: f32| if inside(ray.at(t)) { m.sigma_t.eval(ray.at(t)).x as f64 * 2.0 } else { 0.0 };
        let exact: f64 = {
            let n = 400_000;
            let h = t_max as f64 / n as f64;
            let mut tau = 0.0f64;
            let mut sum = 0.0f64;
            for i in 0..n {
                let t = (i as f64 + 0.5) * h;
                let s = sigma(t as f32);
                sum += s * (-(tau + 0.5 * s * h)).exp() * f(t as f32) * h;
                tau += s * h;
            }
            sum
        };
        let mut steps = Steps::default();
        m.track(&ray, t_max, &mut steps);
        let mut rng = stream(10, Domain::Camera, 0);
        let n = 400_000;
        let mut sum = 0.0f64;
        for i in 0..n {
            let u = glam::Vec2::new(rng.random(), (i as f32 + rng.random::<f32>()) / n as f32);
            let (t, pdf) = seg.sample(u).unwrap();
            let tr = m.transmittance_to(&steps, t).x as f64;
            sum += sigma(t) * tr * f(t) / pdf as f64;
        }
        let got = sum / n as f64;
        assert!((got - exact).abs() < 0.003 * exact, "{got} against {exact}");
    }
}
