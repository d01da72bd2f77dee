//! The global volume photons as a grid of in-scattered light: each
//! medium's photons splatted once per pass into the vertices of a grid
//! over their bounding box (a tent kernel: a photon's power shared among
//! the 8 vertices of its cell by trilinear weights), read along a camera
//! segment cell by cell (the trilinear interpolant of the vertices, a
//! cubic along the segment within a cell, integrated with the
//! transmittance by two-point Gauss–Legendre). A segment's cost is the
//! cells it crosses, not the photons it passes: the beam estimate
//! ([`super::volume_map`]) reads every photon whose sphere the segment
//! crosses, and that grows with the photons stored.
//!
//! Each vertex keeps the power (RGB) and the luminance-weighted sum of the
//! photons' directions; the light's angular distribution at a point is
//! kept as its mean direction m (|m| ≤ 1, the first Legendre moment) and
//! taken to be a Henyey–Greenstein lobe about m of mean cosine |m|. A
//! Henyey–Greenstein phase function of asymmetry g multiplies the l-th
//! Legendre coefficient of the light by g^l, so the light scattered
//! towards the eye is then HG(g |m|) about m: exact in the first two
//! moments (any distribution), exact altogether where the light's
//! distribution is itself such a lobe (light scattered once from a
//! collimated beam in the medium), never negative (a truncated Legendre
//! series is, at |3 g cos| > 1). An isotropic medium needs no direction.
//!
//! The grid's box is the photons' bounding box with vertices on its faces;
//! a vertex's power is divided by the volume of its tent inside the box,
//! so a medium that fills a box (a room of fog, a grid's box of smoke)
//! reads its density without loss at the walls. Its spacing is set by the
//! photons' density, so the estimate converges as photons grow (see
//! [`VolumeGrid::build`]).

use super::volume_map::VolumePhoton;
use crate::math::{Color, Ray};
use crate::medium::{Aabb, Phase};
use glam::Vec3;
use std::collections::HashSet;

/// The most vertices of one medium's grid (24 bytes each: 100 MB); a
/// denser grid's spacing grows to fit.
const MAX_VERTICES: f32 = (1u32 << 22) as f32;

/// The cell's side over the radius of the sphere that holds k photons at
/// their mean density: the blur of the tent splat and trilinear read
/// together (a per-axis variance of h²/3) equals the beam estimate's disk
/// of that radius (r²/4) at √3/2.
const SPACING: f32 = 0.866;

/// Gauss–Legendre's two nodes on [0, 1].
const GL: [f32; 2] = [0.5 - 0.288_675_13, 0.5 + 0.288_675_13];

#[derive(Clone, Debug)]
struct MediumGrid {
    lo: Vec3,
    /// Cell sides.
    h: Vec3,
    /// Cells per axis (vertices one more).
    n: [u32; 3],
    /// Per vertex: power per unit volume (RGB), then the sum of the
    /// photons' directions weighted by their power's luminance, per unit
    /// volume.
    v: Vec<[f32; 6]>,
    /// In a heterogeneous medium, per vertex: the mean extinction σ_t (RGB)
    /// over the vertex's tent, weighted as the tent weighs photons
    /// ([`VolumeGrid::build_weighed`]).
    extinction: Option<Vec<[f32; 3]>>,
    /// While the cells' side is chosen: per vertex, the luminance of the
    /// power of the photons at even and at odd places, per unit volume.
    halves: Vec<[f32; 2]>,
}

/// The global volume photons of a pass as grids, one per medium.
#[derive(Debug, Default)]
pub struct VolumeGrid {
    grids: Vec<Option<MediumGrid>>,
    photons: usize,
}

fn luminance(c: Color) -> f32 {
    crate::texture::luminance(c)
}

/// Corner `corner` (0-7: its x, y and z offsets as bits) of a cell: its
/// offset from the cell's lowest vertex in a grid of `nx` × `ny` vertices
/// a layer, and its trilinear weight at `f` (in [0, 1]³) within the cell.
#[inline]
fn corner(corner: usize, f: Vec3, nx: usize, ny: usize) -> (usize, f32) {
    let (a, b, c) = (corner & 1, (corner >> 1) & 1, corner >> 2);
    let w = (if a == 1 { f.x } else { 1.0 - f.x })
        * (if b == 1 { f.y } else { 1.0 - f.y })
        * (if c == 1 { f.z } else { 1.0 - f.z });
    ((c * ny + b) * nx + a, w)
}

impl VolumeGrid {
    /// The grids of `photons`: per medium, cells of side [`SPACING`] times
    /// the radius of the sphere holding `k` photons at their mean density
    /// over the space they occupy (counted in cells of about `k` photons
    /// were they spread evenly through their box), at most `r_max`, times
    /// `shrink` (a progressive pass's narrowing; 1 in a classic render).
    pub fn build(photons: &[VolumePhoton], k: usize, r_max: f32, shrink: f32) -> Self {
        Self::build_weighed(photons, k, r_max, shrink, &[] as &[Option<fn(Vec3) -> Color>])
    }

    /// [`Self::build`], medium m's grid read as the fluence its photons
    /// carry times the medium's own extinction `extinction[m]` (scaled, RGB)
    /// where one is given, not as the photons' density blurred: for a
    /// heterogeneous medium.
    ///
    /// Photons scatter where σ_s is, so their density is σ_s times the
    /// light arriving (the fluence, weighted by direction), and the grid's
    /// kernel blurs both: in smoke the density's fine structure, which the
    /// scene defines exactly, was blurred with the light's (bias where the
    /// density changes within a cell). Each vertex's power is divided by
    /// the tent-weighted mean of σ_t about it, its expectation for a light
    /// uniform over the tent (the albedo, where constant, cancels), so what
    /// is interpolated is the smooth light alone; a segment then weighs it
    /// by the medium's σ_t · T exactly, as −dT (see [`Self::integrate`]).
    /// The estimate's relative noise is the grid's: the ratio of two
    /// interpolants, one of them exact. The means are found on a lattice of
    /// half the cells' side (Simpson's rule over the tent). With the
    /// density's structure gone from the bias, the cells' side is chosen
    /// from the photons (`MediumGrid::coarser_is_better`): k photons per
    /// cell at their mean density, or 2k, 4k or 8k where the wider cells'
    /// noise saved outweighs their bias.
    pub fn build_weighed<F: Fn(Vec3) -> Color + Sync>(
        photons: &[VolumePhoton],
        k: usize,
        r_max: f32,
        shrink: f32,
        extinction: &[Option<F>],
    ) -> Self {
        let media = photons.iter().map(|p| p.medium as usize + 1).max().unwrap_or(0);
        let mut grids = Vec::with_capacity(media);
        for m in 0..media as u32 {
            let mine: Vec<&VolumePhoton> = photons.iter().filter(|p| p.medium == m).collect();
            let sigma_t =
                extinction.get(m as usize).and_then(|e| e.as_ref()).map(|f| f as &(dyn Fn(Vec3) -> Color + Sync));
            grids.push(MediumGrid::build(&mine, k, r_max, shrink, sigma_t));
        }
        VolumeGrid { grids, photons: photons.len() }
    }

    pub fn len(&self) -> usize {
        self.photons
    }

    /// Medium `m`'s cells' side along x.
    #[cfg(test)]
    fn side(&self, m: u32) -> Option<f32> {
        self.grids.get(m as usize)?.as_ref().map(|g| g.h.x)
    }

    pub fn is_empty(&self) -> bool {
        self.photons == 0
    }

    pub fn memory_bytes(&self) -> usize {
        self.grids
            .iter()
            .flatten()
            .map(|g| {
                g.v.len() * std::mem::size_of::<[f32; 6]>()
                    + g.extinction.as_ref().map_or(0, |e| e.len() * std::mem::size_of::<[f32; 3]>())
            })
            .sum()
    }

    /// The light medium `m` (of phase function `phase`) scatters towards
    /// the eye along `ray` over [0, `t_max`], each distance weighed by
    /// `tr`, the transmittance from the ray's origin to it (called at
    /// growing distances). A grid weighed by the medium's extinction
    /// ([`Self::build_weighed`]) needs `tr` to be the medium's own
    /// transmittance along the ray.
    pub fn integrate(&self, m: u32, phase: &Phase, ray: &Ray, t_max: f32, tr: impl FnMut(f32) -> Color) -> Color {
        match self.grids.get(m as usize) {
            Some(Some(g)) => g.integrate(phase.mean_cosine(), ray, t_max, tr),
            _ => Color::ZERO,
        }
    }
}

impl MediumGrid {
    fn build(
        photons: &[&VolumePhoton],
        k: usize,
        r_max: f32,
        shrink: f32,
        extinction: Option<&(dyn Fn(Vec3) -> Color + Sync)>,
    ) -> Option<Self> {
        if photons.is_empty() {
            return None;
        }
        let (lo, hi) = photons
            .iter()
            .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(a, b), p| (a.min(p.pos), b.max(p.pos)));
        let extent = (hi - lo).max(Vec3::splat(1e-4 * (hi - lo).max_element().max(1e-4)));
        // The space the photons occupy: the coarse cells holding any.
        let coarse = (extent.x * extent.y * extent.z * k as f32 / photons.len() as f32).cbrt().max(1e-6);
        let mut occupied: HashSet<(i32, i32, i32)> = HashSet::with_capacity(photons.len() / k.max(1) + 1);
        for p in photons {
            let c = ((p.pos - lo) / coarse).floor();
            occupied.insert((c.x as i32, c.y as i32, c.z as i32));
        }
        let volume = (occupied.len() as f32 * coarse.powi(3)).min(extent.x * extent.y * extent.z).max(1e-12);
        let density = photons.len() as f32 / volume;
        let r = (3.0 * k as f32 / (4.0 * std::f32::consts::PI * density)).cbrt();
        let mut side = SPACING * if r.is_finite() { r.min(r_max) } else { r_max } * shrink;
        let cells = |side: f32| (extent / side).ceil().max(Vec3::ONE);
        let vertices = |c: Vec3| (c.x + 1.0) * (c.y + 1.0) * (c.z + 1.0);
        while vertices(cells(side)) > MAX_VERTICES {
            side *= 1.25;
        }
        let Some(sigma_t) = extinction else {
            return Some(Self::splat(photons, lo, extent, side, None));
        };
        // Weighed by the extinction: the cells' side chosen among k, 2k, 4k
        // and 8k photons by the photons themselves (see `coarser_is_better`).
        let mut best = Self::splat(photons, lo, extent, side, Some(sigma_t));
        for step in 1..=3 {
            let wider = side * 2f32.powf(step as f32 / 3.0);
            if vertices(cells(wider)) < 8.0 {
                break;
            }
            let next = Self::splat(photons, lo, extent, wider, Some(sigma_t));
            if !best.coarser_is_better(&next, photons, sigma_t) {
                break;
            }
            best = next;
        }
        best.halves = Vec::new();
        Some(best)
    }

    /// The grid of cells of about `side` over the box from `lo` of
    /// `extent`, the photons splatted into it; weighed by the extinction
    /// `sigma_t` where given, with the two halves of the photons (even and
    /// odd places) kept apart as well, for [`Self::coarser_is_better`].
    fn splat(
        photons: &[&VolumePhoton],
        lo: Vec3,
        extent: Vec3,
        side: f32,
        sigma_t: Option<&(dyn Fn(Vec3) -> Color + Sync)>,
    ) -> Self {
        let c = (extent / side).ceil().max(Vec3::ONE);
        let n = [c.x as u32, c.y as u32, c.z as u32];
        let h = extent / c;
        let (nx, ny) = (n[0] as usize + 1, n[1] as usize + 1);
        let mut v = vec![[0.0f32; 6]; nx * ny * (n[2] as usize + 1)];
        let mut halves = vec![[0.0f32; 2]; if sigma_t.is_some() { v.len() } else { 0 }];
        // In the photons' order, one after another: the same sums on any
        // thread count.
        for (index, p) in photons.iter().enumerate() {
            let u = ((p.pos - lo) / h).clamp(Vec3::ZERO, c);
            let cell = u.floor().min(c - Vec3::ONE);
            let f = u - cell;
            let (i, j, l) = (cell.x as usize, cell.y as usize, cell.z as usize);
            let dir = p.direction() * luminance(p.power);
            for c in 0..8 {
                let (offset, w) = corner(c, f, nx, ny);
                let at = (l * ny + j) * nx + i + offset;
                let add = [p.power.x, p.power.y, p.power.z, dir.x, dir.y, dir.z];
                for (s, a) in v[at].iter_mut().zip(add) {
                    *s += w * a;
                }
                if let Some(half) = halves.get_mut(at) {
                    half[index % 2] += w * luminance(p.power);
                }
            }
        }
        // Each vertex over its tent's volume inside the box: half a cell's
        // span on each axis where it lies on a face.
        let cell_volume = h.x * h.y * h.z;
        for zi in 0..=n[2] as usize {
            for yi in 0..ny {
                for xi in 0..nx {
                    let half = |i: usize, last: usize| if i == 0 || i == last { 0.5 } else { 1.0 };
                    let inside = cell_volume * half(xi, nx - 1) * half(yi, ny - 1) * half(zi, n[2] as usize);
                    let at = (zi * ny + yi) * nx + xi;
                    for s in &mut v[at] {
                        *s /= inside;
                    }
                    if let Some(half) = halves.get_mut(at) {
                        half[0] /= inside;
                        half[1] /= inside;
                    }
                }
            }
        }
        let mut grid = MediumGrid { lo, h, n, v, extinction: None, halves };
        if let Some(f) = sigma_t {
            grid.extinction = Some(grid.tent_means(f));
        }
        grid
    }

    /// Whether the grid `wider` (cells 2^⅓ times this one's side, twice
    /// the photons per cell) estimates the light σ_t·F with less squared
    /// error than this one, judged at every 8th photon (where the light is
    /// scattered, as the photons are), each channel's luminance.
    ///
    /// A kernel estimate's bias grows as the square of its width, so the
    /// wider grid's bias is 2^⅔ times this one's, and the difference of
    /// the two estimates is 2^⅔ − 1 of this one's bias, plus noise. The
    /// noise is measured by the two halves of the photons, each an
    /// estimate of its own: (a − b)²/4 is an unbiased estimate of the full
    /// estimate's variance, and of the difference's where a and b are the
    /// halves' differences. So Σ of the squared difference less its noise
    /// estimates (2^⅔ − 1)² B², B² this grid's squared bias; the wider grid
    /// adds (2^(4/3) − 1) B² of squared bias and saves the difference of
    /// the two variances. Lepski's principle, with the bias's rate.
    fn coarser_is_better(
        &self,
        wider: &MediumGrid,
        photons: &[&VolumePhoton],
        sigma_t: &(dyn Fn(Vec3) -> Color + Sync),
    ) -> bool {
        let c = 2f64.powf(2.0 / 3.0);
        let (mut difference, mut saved) = (0.0f64, 0.0f64);
        for p in photons.iter().step_by(8) {
            let weight = luminance(sigma_t(p.pos)) as f64;
            let (Some(fine), Some(coarse)) = (self.light_at(p.pos), wider.light_at(p.pos)) else { continue };
            let (d, da, db) = (fine[0] - coarse[0], fine[1] - coarse[1], fine[2] - coarse[2]);
            difference += weight * weight * (d * d - (da - db) * (da - db) / 4.0);
            saved += weight * weight * ((fine[1] - fine[2]).powi(2) - (coarse[1] - coarse[2]).powi(2)) / 4.0;
        }
        let bias = difference / ((c - 1.0) * (c - 1.0));
        (c * c - 1.0) * bias < saved
    }

    /// The light (power over the tent's mean extinction, luminance) at
    /// `x`: of all the photons, of the even ones and of the odd ones (each
    /// half doubled); none where the extinction about `x` is zero.
    fn light_at(&self, x: Vec3) -> Option<[f64; 3]> {
        let e = self.extinction.as_ref()?;
        let (base, f) = self.locate(x);
        let mean = luminance(Self::read_extinction(e, self.n, base, f)) as f64;
        if !(mean > 0.0) {
            return None;
        }
        let nx = self.n[0] as usize + 1;
        let ny = self.n[1] as usize + 1;
        let mut halves = [0.0f64; 2];
        for c in 0..8 {
            let (offset, w) = corner(c, f, nx, ny);
            let h = self.halves[base + offset];
            halves[0] += (w * h[0]) as f64;
            halves[1] += (w * h[1]) as f64;
        }
        let (a, b) = (2.0 * halves[0] / mean, 2.0 * halves[1] / mean);
        Some([(a + b) / 2.0, a, b])
    }

    /// The cell holding `x` (the index of its lowest vertex) and `x`'s
    /// place in it, in [0, 1]³.
    fn locate(&self, x: Vec3) -> (usize, Vec3) {
        let c = Vec3::new(self.n[0] as f32, self.n[1] as f32, self.n[2] as f32);
        let u = ((x - self.lo) / self.h).clamp(Vec3::ZERO, c);
        let cell = u.floor().min(c - Vec3::ONE);
        let (nx, ny) = (self.n[0] as usize + 1, self.n[1] as usize + 1);
        ((cell.z as usize * ny + cell.y as usize) * nx + cell.x as usize, u - cell)
    }

    /// Per vertex, the mean of `f` over the part of its tent inside the
    /// box, weighted by the tent: `f` on a lattice of half the cells' side,
    /// then along each axis in turn Simpson's rule on each half of the
    /// tent, which is linear there: ⅓, ⅓, ⅓ (on a face, where half the
    /// tent is inside, ⅓ at the vertex and ⅔ inwards); exact for `f`
    /// quadratic along the axis, a density varying within a cell read
    /// closely (a sinusoid of a period of 5.4 cells: its tent mean's amplitude
    /// 0.890 for 0.892, where the trapezoidal rule's ¼, ½, ¼ gives 0.918).
    /// Rows of the lattice are evaluated in parallel, each by itself: the
    /// same values on any number of threads.
    fn tent_means(&self, f: impl Fn(Vec3) -> Color + Sync) -> Vec<[f32; 3]> {
        use rayon::prelude::*;
        const THIRD: f32 = 1.0 / 3.0;
        let [cx, cy, cz] = self.n.map(|c| c as usize);
        let (lx, ly, lz) = (2 * cx + 1, 2 * cy + 1, 2 * cz + 1);
        let half = self.h * 0.5;
        // The lattice, one row of x per (y, z).
        let mut lattice = vec![[0.0f32; 3]; lx * ly * lz];
        lattice.par_chunks_mut(lx).enumerate().for_each(|(row, out)| {
            let (yi, zi) = (row % ly, row / ly);
            for (xi, o) in out.iter_mut().enumerate() {
                let p = self.lo + half * Vec3::new(xi as f32, yi as f32, zi as f32);
                let c = f(p);
                *o = if c.is_finite() { [c.x.max(0.0), c.y.max(0.0), c.z.max(0.0)] } else { [0.0; 3] };
            }
        });
        // Along one axis: from `len` = 2 c + 1 lattice points to c + 1
        // vertices, at stride `stride` in `data`, `count` lines.
        let filter = |data: &[[f32; 3]], dims: [usize; 3], axis: usize| -> (Vec<[f32; 3]>, [usize; 3]) {
            let mut out_dims = dims;
            out_dims[axis] = dims[axis] / 2 + 1;
            let strides = [1, dims[0], dims[0] * dims[1]];
            let out_strides = [1, out_dims[0], out_dims[0] * out_dims[1]];
            let mut out = vec![[0.0f32; 3]; out_dims[0] * out_dims[1] * out_dims[2]];
            let last = out_dims[axis] - 1;
            for (o, slot) in out.iter_mut().enumerate() {
                let idx = [o % out_dims[0], (o / out_strides[1]) % out_dims[1], o / out_strides[2]];
                let mut src = 0;
                for a in 0..3 {
                    src += if a == axis { 2 * idx[a] } else { idx[a] } * strides[a];
                }
                let s = strides[axis];
                let taps: &[(isize, f32)] = match idx[axis] {
                    _ if last == 0 => &[(0, 1.0)],
                    0 => &[(0, THIRD), (1, 2.0 * THIRD)],
                    i if i == last => &[(-1, 2.0 * THIRD), (0, THIRD)],
                    _ => &[(-1, THIRD), (0, THIRD), (1, THIRD)],
                };
                let mut sum = [0.0f32; 3];
                for &(d, w) in taps {
                    let v = data[(src as isize + d * s as isize) as usize];
                    for c in 0..3 {
                        sum[c] += w * v[c];
                    }
                }
                *slot = sum;
            }
            (out, out_dims)
        };
        let (a, dims) = filter(&lattice, [lx, ly, lz], 0);
        let (b, dims) = filter(&a, dims, 1);
        filter(&b, dims, 2).0
    }

    /// The vertices' mean extinction interpolated at `f` within the cell
    /// at `base`, as [`Self::read`] interpolates their power.
    #[inline]
    fn read_extinction(e: &[[f32; 3]], n: [u32; 3], base: usize, f: Vec3) -> Color {
        let nx = n[0] as usize + 1;
        let ny = n[1] as usize + 1;
        let mut out = Color::ZERO;
        for c in 0..8 {
            let (offset, w) = corner(c, f, nx, ny);
            let s = e[base + offset];
            out += w * Color::new(s[0], s[1], s[2]);
        }
        out
    }

    /// The vertices' values interpolated at `f` (in [0, 1]³) within the
    /// cell at `base` (the index of its lowest vertex).
    #[inline]
    fn read(&self, base: usize, f: Vec3) -> [f32; 6] {
        let nx = self.n[0] as usize + 1;
        let ny = self.n[1] as usize + 1;
        let mut out = [0.0f32; 6];
        for c in 0..8 {
            let (offset, w) = corner(c, f, nx, ny);
            let s = &self.v[base + offset];
            for (o, x) in out.iter_mut().zip(s) {
                *o += w * x;
            }
        }
        out
    }

    fn integrate(&self, g: f32, ray: &Ray, t_max: f32, mut tr: impl FnMut(f32) -> Color) -> Color {
        let cells = Vec3::new(self.n[0] as f32, self.n[1] as f32, self.n[2] as f32);
        let hi = self.lo + self.h * cells;
        let Some((t0, t1)) = (Aabb { lo: self.lo, hi }).clip(ray, t_max) else { return Color::ZERO };
        if !(t1 > t0) {
            return Color::ZERO;
        }
        let out = -ray.dir;
        let (nx, ny) = (self.n[0] as usize + 1, self.n[1] as usize + 1);
        // Amanatides and Woo's walk through the cells between vertex planes.
        let start = ((ray.at(t0) - self.lo) / self.h).clamp(Vec3::ZERO, cells - Vec3::splat(1e-3));
        let mut cell = [0i64; 3];
        let mut step = [0i64; 3];
        let mut t_next = [f32::INFINITY; 3];
        let mut t_delta = [f32::INFINITY; 3];
        for a in 0..3 {
            let c = start[a].floor().min(cells[a] - 1.0).max(0.0);
            cell[a] = c as i64;
            let d = ray.dir[a];
            if d > 0.0 {
                step[a] = 1;
                t_delta[a] = self.h[a] / d;
                t_next[a] = t0 + (c + 1.0 - start[a]) * t_delta[a];
            } else if d < 0.0 {
                step[a] = -1;
                t_delta[a] = -self.h[a] / d;
                t_next[a] = t0 + (start[a] - c) * t_delta[a];
            }
        }
        // The vertices' power as light scattered towards the eye: the
        // mean direction read from the luminance-weighted sum, the phase
        // function about it (see the module's notes).
        let scattered = |x: [f32; 6]| -> Option<(Color, f32)> {
            let power = Color::new(x[0], x[1], x[2]);
            let lum = luminance(power);
            if !(lum > 0.0) {
                return None;
            }
            let phase = if g == 0.0 {
                1.0 / (4.0 * std::f32::consts::PI)
            } else {
                let mean = Vec3::new(x[3], x[4], x[5]) / lum;
                let len_m = mean.length().min(1.0);
                if len_m > 1e-6 {
                    Phase::HenyeyGreenstein { g: g * len_m }.eval(mean / mean.length(), out)
                } else {
                    1.0 / (4.0 * std::f32::consts::PI)
                }
            };
            Some((power, phase))
        };
        let mut sum = Color::ZERO;
        let mut t = t0;
        // Weighed by extinction: the transmittance at the piece's start.
        let mut tr_start = match self.extinction {
            Some(_) => tr(t0),
            None => Color::ZERO,
        };
        while t < t1 {
            let axis = if t_next[0] <= t_next[1] && t_next[0] <= t_next[2] {
                0
            } else if t_next[1] <= t_next[2] {
                1
            } else {
                2
            };
            let end = t_next[axis].min(t1);
            if end > t {
                let base = (cell[2] as usize * ny + cell[1] as usize) * nx + cell[0] as usize;
                let corner = self.lo + self.h * Vec3::new(cell[0] as f32, cell[1] as f32, cell[2] as f32);
                let len = end - t;
                let local = |s: f32| ((ray.at(s) - corner) / self.h).clamp(Vec3::ZERO, Vec3::ONE);
                match &self.extinction {
                    // ∫ T σ_t F p dt = ∫ F p (−dT): each half of the piece
                    // its fall in transmittance times the light at its
                    // middle.
                    Some(e) => {
                        let mid = t + 0.5 * len;
                        let (tr_mid, tr_end) = (tr(mid), tr(end));
                        for (s, fall) in [(t + 0.25 * len, tr_start - tr_mid), (t + 0.75 * len, tr_mid - tr_end)] {
                            let f = local(s);
                            let Some((power, phase)) = scattered(self.read(base, f)) else { continue };
                            let mean = Self::read_extinction(e, self.n, base, f);
                            let light = Color::new(
                                if mean.x > 0.0 { power.x / mean.x } else { 0.0 },
                                if mean.y > 0.0 { power.y / mean.y } else { 0.0 },
                                if mean.z > 0.0 { power.z / mean.z } else { 0.0 },
                            );
                            sum += light * fall.max(Color::ZERO) * phase;
                        }
                        tr_start = tr_end;
                    }
                    None => {
                        for node in GL {
                            let s = t + node * len;
                            let Some((power, phase)) = scattered(self.read(base, local(s))) else { continue };
                            sum += power * tr(s) * (0.5 * len * phase);
                        }
                    }
                }
            }
            if t_next[axis] >= t1 {
                break;
            }
            t = end;
            cell[axis] += step[axis];
            if cell[axis] < 0 || cell[axis] >= self.n[axis] as i64 {
                break;
            }
            t_next[axis] += t_delta[axis];
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photon::volume_map::VolumeMap;
    use crate::sampling::{stream, Domain};
    use rand::RngExt;

    fn uniform(n: usize, seed: u64, dir: impl Fn(&mut crate::sampling::Rng) -> Vec3) -> Vec<VolumePhoton> {
        let mut rng = stream(seed, Domain::Camera, 3);
        (0..n)
            .map(|_| {
                let p = Vec3::new(rng.random(), rng.random(), rng.random());
                let d = dir(&mut rng);
                VolumePhoton::new(p, Color::splat(1.0 / n as f32), d, 0)
            })
            .collect()
    }

    /// With photons of total power Φ spread uniformly through a unit cube,
    /// isotropic, a segment of length L reads Φ L / (4π) on average,
    /// including segments that end on the cube's faces (the vertices on a
    /// face are divided by the half of their tent inside) and ones that
    /// start outside it.
    #[test]
    fn a_uniform_density_reads_its_integral_up_to_the_walls() {
        let photons = uniform(200_000, 5, |_| Vec3::Z);
        let grid = VolumeGrid::build(&photons, 24, 0.2, 1.0);
        let mut rng = stream(6, Domain::Camera, 4);
        let iso = Phase::Isotropic;
        for (origin, dir, len, expect) in [
            (0.0f32, Vec3::X, 1.0f32, 1.0f32),
            (0.97, Vec3::X, 0.03, 0.03),
            (0.03, -Vec3::X, 0.03, 0.03),
            (-1.0, Vec3::X, 1.2, 0.2),
        ] {
            let rays = 2000;
            let mut sum = 0.0f64;
            for _ in 0..rays {
                let (y, z) = (rng.random::<f32>(), rng.random::<f32>());
                let ray = Ray::new(Vec3::new(origin, y, z), dir);
                sum += grid.integrate(0, &iso, &ray, len, |_| Color::ONE).x as f64;
            }
            let mean = sum / rays as f64 * 4.0 * std::f64::consts::PI;
            assert!((mean / expect as f64 - 1.0).abs() < 0.03, "from {origin} along {dir}: {mean} against {expect}");
        }
    }

    /// The grid and the beam estimate agree on the same photons, weighed by
    /// a transmittance and a Henyey–Greenstein phase function, where the
    /// photons' directions are themselves a Henyey–Greenstein lobe about
    /// one axis (which the grid's moment keeps exactly): mean over many
    /// segments within 2%, and the grid reads a forward-scattered lobe
    /// brighter than a backward one as the beam does.
    #[test]
    fn the_grid_agrees_with_the_beam_estimate() {
        let g_light = 0.5;
        let lobe = Phase::HenyeyGreenstein { g: g_light };
        let photons = uniform(300_000, 8, |rng| lobe.sample(Vec3::X, glam::Vec2::new(rng.random(), rng.random())).0);
        let grid = VolumeGrid::build(&photons, 24, 0.2, 1.0);
        let map = VolumeMap::build(photons, 24, 0.2, 1.0);
        let phase = Phase::HenyeyGreenstein { g: 0.6 };
        let sigma = 0.8f32;
        let mut rng = stream(10, Domain::Camera, 5);
        for dir in [Vec3::X, -Vec3::X, Vec3::Y] {
            let (mut a, mut b) = (0.0f64, 0.0f64);
            for _ in 0..1500 {
                let (u, v) = (0.1 + 0.8 * rng.random::<f32>(), 0.1 + 0.8 * rng.random::<f32>());
                let o = if dir == Vec3::Y {
                    Vec3::new(u, 0.0, v)
                } else if dir == Vec3::X {
                    Vec3::new(0.0, u, v)
                } else {
                    Vec3::new(1.0, u, v)
                };
                let ray = Ray::new(o, dir);
                a += grid.integrate(0, &phase, &ray, 1.0, |t| Color::splat((-sigma * t).exp())).x as f64;
                map.beam(&ray, 1.0, |c| {
                    b += (c.photon.power.x * c.kernel * phase.eval(c.photon.direction(), -dir) * (-sigma * c.t).exp())
                        as f64
                });
            }
            println!("{dir}: grid {a} beam {b}");
            assert!((a / b - 1.0).abs() < 0.02, "{dir}: grid {a} beam {b}");
        }
    }

    /// A medium's grid holds only the photons that scattered in it: a
    /// medium without photons (or past the last) reads nothing.
    #[test]
    fn media_are_kept_apart() {
        let mut photons = uniform(10_000, 12, |_| Vec3::Z);
        for p in photons.iter_mut().step_by(2) {
            p.medium = 2;
        }
        let grid = VolumeGrid::build(&photons, 24, 0.2, 1.0);
        let ray = Ray::new(Vec3::new(0.0, 0.5, 0.5), Vec3::X);
        let iso = Phase::Isotropic;
        let (a, b, c) = (
            grid.integrate(0, &iso, &ray, 1.0, |_| Color::ONE),
            grid.integrate(1, &iso, &ray, 1.0, |_| Color::ONE),
            grid.integrate(2, &iso, &ray, 1.0, |_| Color::ONE),
        );
        assert_eq!(b, Color::ZERO);
        assert!(a.x > 0.0 && c.x > 0.0);
        assert!(grid.integrate(3, &iso, &ray, 1.0, |_| Color::ONE) == Color::ZERO);
    }

    /// Photons whose density follows a medium's extinction at the grid's
    /// own scale (σ_t = 1 + 0.9 sin(16πx), a period of about five cells),
    /// under light uniform through the cube: read along y at fixed x, with
    /// the medium's transmittance, the grid weighed by the extinction finds
    /// ∫ T σ_t F p dt within 4% at every x, crests and troughs alike, where
    /// the photons' blurred density reads the troughs far too bright.
    #[test]
    fn a_grid_weighed_by_extinction_reads_the_density_s_fine_structure() {
        let sigma = |x: f32| 1.0 + 0.9 * (16.0 * std::f32::consts::PI * x).sin();
        let n = 400_000;
        let mut rng = stream(21, Domain::Camera, 6);
        let mut photons = Vec::with_capacity(n);
        while photons.len() < n {
            let p = Vec3::new(rng.random(), rng.random(), rng.random());
            if rng.random::<f32>() * 1.9 < sigma(p.x) {
                photons.push(VolumePhoton::new(p, Color::splat(1.0 / n as f32), Vec3::Z, 0));
            }
        }
        // ∫σ_t over the cube is 1: the fluence F is 1.
        let blurred = VolumeGrid::build(&photons, 24, 0.2, 1.0);
        let weighed = VolumeGrid::build_weighed(&photons, 24, 0.2, 1.0, &[Some(|p: Vec3| Color::splat(sigma(p.x)))]);
        let iso = Phase::Isotropic;
        let (mut worst_weighed, mut worst_blurred) = (0.0f64, 0.0f64);
        for j in 0..16 {
            let x = 0.3 + j as f32 / 128.0;
            let s = sigma(x);
            let expect = (1.0 - (-s as f64).exp()) / (4.0 * std::f64::consts::PI);
            let (mut a, mut b) = (0.0f64, 0.0f64);
            let rays = 300;
            for i in 0..rays {
                let z = 0.05 + 0.9 * (i as f32 + 0.5) / rays as f32;
                let ray = Ray::new(Vec3::new(x, 0.0, z), Vec3::Y);
                let tr = |t: f32| Color::splat((-s * t).exp());
                a += weighed.integrate(0, &iso, &ray, 1.0, tr).x as f64;
                b += blurred.integrate(0, &iso, &ray, 1.0, tr).x as f64;
            }
            let (ea, eb) = (a / rays as f64 / expect - 1.0, b / rays as f64 / expect - 1.0);
            println!("x {x:.4} σ {s:.3}: weighed {ea:+.4}, blurred {eb:+.4}");
            worst_weighed = worst_weighed.max(ea.abs());
            worst_blurred = worst_blurred.max(eb.abs());
        }
        assert!(worst_weighed < 0.04, "weighed by extinction: off by {worst_weighed}");
        assert!(worst_blurred > 0.3, "the blurred density should miss the troughs: {worst_blurred}");
    }

    /// The cells' side of a weighed grid follows the light: where it is
    /// uniform the photons choose wider cells than k's (less noise, no
    /// bias to add); where it varies across the cube (1 + 0.9 sin(8πx),
    /// which the widest cells would flatten by a quarter), the wider
    /// cells' bias outweighs their noise and the side stays narrower.
    #[test]
    fn the_cells_widen_where_the_light_is_smooth() {
        let n = 400_000;
        let build = |varying: bool| {
            let mut rng = stream(31, Domain::Camera, 7);
            let photons: Vec<VolumePhoton> = (0..n)
                .map(|_| {
                    let p = Vec3::new(rng.random(), rng.random(), rng.random());
                    let light = if varying { 1.0 + 0.9 * (8.0 * std::f32::consts::PI * p.x).sin() } else { 1.0 };
                    let power = light / n as f32;
                    VolumePhoton::new(p, Color::splat(power), Vec3::Z, 0)
                })
                .collect();
            let plain = VolumeGrid::build(&photons, 24, 0.2, 1.0).side(0).unwrap();
            let weighed =
                VolumeGrid::build_weighed(&photons, 24, 0.2, 1.0, &[Some(|_: Vec3| Color::ONE)]).side(0).unwrap();
            (plain, weighed)
        };
        let (plain, uniform) = build(false);
        let (_, varying) = build(true);
        println!("k's side {plain}, uniform light {uniform}, varying light {varying}");
        assert!(uniform > 1.5 * plain, "uniform light: {uniform} against k's {plain}");
        assert!(varying < uniform, "varying light: {varying} against uniform light's {uniform}");
    }
}
