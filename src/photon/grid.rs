//! A uniform grid over a photon map's bounds whose cells hold contiguous
//! ranges of the map's photons: most lookups read a few rows of cells in
//! memory order instead of descending the kd-tree.

use super::Photon;
use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;

/// A uniform grid over the map's bounds whose cells hold contiguous ranges
/// of the photons (sorted by cell, rows along x, so a row of cells is one
/// range). A lookup reads a few rows of photons in memory order instead of
/// descending the kd-tree, which visits many leaves for ~100 photons (77%
/// of the caustic estimates need more than half the cap; the global map's
/// cells are sized for its much smaller radii). Where the rows hold too
/// many photons (the caustic's focus) the tree answers. A lookup whose
/// rows are all empty finds nothing without either.
pub(crate) struct CellGrid {
    lo: Vec3,
    inv_cell: f32,
    dims: [i32; 3],
    /// `start[c]..start[c + 1]`: the photons of cell `c` (x fastest).
    pub(crate) start: Vec<u32>,
}

/// Cells at most (4 bytes each); a larger grid gets wider cells.
pub(crate) const GRID_MAX_CELLS: f32 = 4_194_304.0;

/// Grid cells per lookup radius cap: the rows a lookup at the cap reads
/// cover (2 + 1/2)^2 r^2 of a surface on average, 1.3x the 4 r^2 a square
/// around the disk would, in at most 5 x 5 rows.
pub(crate) const GRID_CELLS_PER_CAP: f32 = 2.0;

/// Rows a grid lookup reads at most (more: the tree answers).
pub(crate) const GRID_MAX_ROWS: usize = 64;

/// Photons a grid lookup scans at most (more: the tree answers, as it is
/// faster than a scan of ~2,000 photons).
pub(crate) const GRID_MAX_SCAN: u32 = 2048;

impl CellGrid {
    /// The grid for `photons` (within bounds `(lo, hi)`) with cells `cell`
    /// wide (wider if the bounds would need too many), and the photons sorted by cell, keeping their
    /// order within a cell.
    /// Also returns, for each photon's place in the given order, its place
    /// in the sorted one (for a tree built in the given order).
    /// With `at_photons` (a map searched only at its own photons, which has
    /// no tree), no grid where it would not pay, and no places.
    pub(crate) fn build(
        photons: &[Photon],
        (lo, hi): (Vec3, Vec3),
        cell: f32,
        at_photons: bool,
    ) -> Option<(Self, Vec<Photon>, Option<Vec<u32>>)> {
        let extent = hi - lo;
        if photons.is_empty() || !(cell > 0.0) || !extent.is_finite() || !cell.is_finite() {
            return None;
        }
        // Widen the cells until the grid is small enough. (Scaling by the
        // cube root of the excess undershoots on flat extents: a floor
        // 1e5 wide with 5 mm cells would have kept 2e9 cells.)
        let cells = |c: f32| ((extent / c).floor() + 1.0).element_product();
        let mut cell = cell;
        while cells(cell) > GRID_MAX_CELLS {
            cell *= 1.25;
        }
        let d = (extent / cell).as_ivec3() + 1;
        let mut grid = CellGrid { lo, inv_cell: 1.0 / cell, dims: [d.x, d.y, d.z], start: Vec::new() };
        // Sorted by (cell, position in the order given: Morton, or as
        // traced): that order survives within cells, and the sort runs on
        // every thread (a serial counting sort of the global map's 4.9 M
        // photons took 0.3 s).
        let n_cells = (d.x * d.y * d.z) as usize;
        let cell_index: Vec<u32> = photons.par_iter().map(|p| grid.index(grid.cell_of(p.position())) as u32).collect();
        let mut start = vec![0u32; n_cells + 1];
        for &c in &cell_index {
            start[c as usize + 1] += 1;
        }
        if at_photons {
            // Searches at the photons themselves read, around a photon's
            // own cell, a few cells like it: where a photon's cell holds
            // GRID_MAX_SCAN / 9 photons on average, most would go to the
            // tree anyway (the global map at 1e7 photons), and the grid
            // would cost its sort and memory for nothing.
            let typical =
                cell_index.par_iter().map(|&c| start[c as usize + 1] as f64).sum::<f64>() / photons.len() as f64;
            if 9.0 * typical > GRID_MAX_SCAN as f64 {
                return None;
            }
        }
        let mut keys: Vec<u64> =
            cell_index.par_iter().enumerate().map(|(i, &c)| ((c as u64) << 32) | i as u64).collect();
        drop(cell_index);
        keys.par_sort_unstable();
        for c in 0..n_cells {
            start[c + 1] += start[c];
        }
        let sorted: Vec<Photon> = keys.par_iter().map(|&key| photons[key as u32 as usize]).collect();
        let place = (!at_photons).then(|| {
            let mut place = vec![0u32; keys.len()];
            for (j, &key) in keys.iter().enumerate() {
                place[key as u32 as usize] = j as u32;
            }
            place
        });
        grid.start = start;
        Some((grid, sorted, place))
    }

    /// The cell holding `x`, clamped to the grid.
    pub(crate) fn cell_of(&self, x: Vec3) -> [i32; 3] {
        let c = (x - self.lo) * self.inv_cell;
        [0, 1, 2].map(|a| (c[a].floor() as i32).clamp(0, self.dims[a] - 1))
    }

    pub(crate) fn index(&self, c: [i32; 3]) -> usize {
        ((c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]) as usize
    }

    /// The cells (first and last on each axis) that meet the box of
    /// half-width `r` around `x`, clamped to the grid (first > last where
    /// the box misses it); `None` where the box is not finite. The box is
    /// padded by a relative 1e-5 so that rounding cannot leave out a photon
    /// at distance `r`.
    #[inline]
    pub(crate) fn cell_box(&self, x: Vec3, r: f32) -> Option<([i32; 3], [i32; 3])> {
        let pad = r * 1e-5 + (x - self.lo).abs().max_element() * 1e-6;
        let lo = (x - (r + pad) - self.lo) * self.inv_cell;
        let hi = (x + (r + pad) - self.lo) * self.inv_cell;
        if !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        let (mut a, mut b) = ([0i32; 3], [0i32; 3]);
        for ax in 0..3 {
            a[ax] = (lo[ax].floor() as i32).max(0);
            b[ax] = (hi[ax].floor() as i32).min(self.dims[ax] - 1);
            if a[ax] > b[ax] {
                return Some(([0; 3], [-1; 3]));
            }
        }
        Some((a, b))
    }

    /// The photons of each non-empty row of cells in `cell_box`, in index
    /// order.
    pub(crate) fn each_row(&self, (a, b): ([i32; 3], [i32; 3]), mut f: impl FnMut(u32, u32)) {
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                let row = self.index([0, y, z]);
                let (s, e) = (self.start[row + a[0] as usize], self.start[row + b[0] as usize + 1]);
                if e > s {
                    f(s, e);
                }
            }
        }
    }

    /// The ranges of photons in the rows of cells that meet the box of
    /// half-width `r` around `x`, and their total length; `None` when there
    /// are more than [`GRID_MAX_ROWS`] rows or the box is not finite.
    pub(crate) fn rows(&self, x: Vec3, r: f32, rows: &mut [(u32, u32); GRID_MAX_ROWS]) -> Option<(usize, u32)> {
        let (a, b) = self.cell_box(x, r)?;
        if ((b[1] - a[1] + 1) * (b[2] - a[2] + 1)) as usize > GRID_MAX_ROWS {
            return None;
        }
        let (mut n, mut total) = (0, 0);
        self.each_row((a, b), |s, e| {
            rows[n] = (s, e);
            n += 1;
            total += e - s;
        });
        Some((n, total))
    }

    /// The squared radius that would hold ~`k` of the `total` photons in
    /// the rows around `x` at radius `r` if they were spread evenly over a
    /// plane through the rows' box (a guess for the search's speed only:
    /// the answer does not depend on it); `None` where there is none.
    pub(crate) fn crowded_radius2(&self, x: Vec3, r: f32, total: u32, k: usize) -> Option<f32> {
        let (a, b) = self.cell_box(x, r)?;
        let mut sides = [0, 1, 2].map(|ax| (b[ax] - a[ax] + 1).max(0) as f32 / self.inv_cell);
        sides.sort_by(f32::total_cmp);
        let area = sides[1] * sides[2];
        let r2 = 1.5 * k as f32 * area / (PI * total as f32);
        (r2 > 0.0 && r2.is_finite()).then_some(r2)
    }
}
