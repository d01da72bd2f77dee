//! Local majorants of a heterogeneous medium: a coarse grid over its
//! volume's unit cube, each cell holding the largest σ_t any lookup inside
//! it reads, and the walk along a ray through those cells. Delta and ratio
//! tracking draw their tentative collisions at each cell's own majorant
//! instead of the whole volume's (pbrt-v4's `MajorantGrid` and its DDA
//! iterator, Pharr, Jakob and Humphreys 2023, §11.4; Mitsuba 3's
//! `majorant_resolution_factor`): both stay unbiased for any bound at or
//! above σ_t, and where a plume is dense in a few puffs and thin or empty
//! elsewhere (suite scene 14-smoke: its cells' mean is 1/30 of its
//! largest) most tentative collisions of a global majorant are null ones,
//! each a grid lookup.

use super::volume::Grid;
use crate::math::Ray;
use glam::{Affine3A, Vec3};
use std::ops::ControlFlow;

/// Fine cells along each side of a coarse one: smaller coarse cells bound
/// σ_t more tightly but cost a walk step more often (suite scene
/// 14-smoke's 48³ grid: 6³ coarse cells, their mean majorant a sixth of
/// the global one).
const CELLS_PER_MAJORANT: u32 = 8;

/// The most coarse cells along a side.
const MAX_RES: u32 = 64;

/// A heterogeneous medium's majorants, scaled by its `scale`.
#[derive(Clone, Debug)]
pub struct Majorants {
    res: [u32; 3],
    /// Per coarse cell, x fastest.
    values: Vec<f32>,
    /// World to coarse-cell coordinates: the unit cube is [0, res].
    to_cells: Affine3A,
    /// Whether the volume's world box is exactly its unit cube's image
    /// (a placement that maps axes onto axes): then every point of a
    /// segment clipped to the box lies in some coarse cell, up to rounding.
    aligned: bool,
    /// The whole volume's majorant: for the parts of the box outside the
    /// unit cube (where a lookup reads by the wrap mode) when not aligned.
    global: f32,
}

impl Majorants {
    /// The majorants of `grid`'s values times `scale`; `global` bounds
    /// them all.
    pub fn new(grid: &Grid, scale: f32, global: f32) -> Majorants {
        let n = grid.data.res;
        let res = n.map(|r| r.div_ceil(CELLS_PER_MAJORANT).clamp(1, MAX_RES));
        // A lookup at fine coordinate x reads cells floor(x - 1/2) and
        // the next (trilinear) or floor(x) (nearest); one fine cell more on
        // each side also covers rounding at the coarse cells' faces.
        let span = |axis: usize, k: u32| -> (i32, i32) {
            let (n, m) = (n[axis] as u64, res[axis] as u64);
            let lo = (k as u64 * n / m) as i32 - 1;
            let hi = ((k as u64 + 1) * n).div_ceil(m) as i32;
            (lo, hi)
        };
        let mut values = Vec::with_capacity((res[0] * res[1] * res[2]) as usize);
        for z in 0..res[2] {
            let (z0, z1) = span(2, z);
            for y in 0..res[1] {
                let (y0, y1) = span(1, y);
                for x in 0..res[0] {
                    let (x0, x1) = span(0, x);
                    let m = grid.block_max([x0, y0, z0], [x1, y1, z1]) * scale;
                    values.push(m.min(global));
                }
            }
        }
        let to_local = *grid.to_local();
        let cells = Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
        let to_cells = Affine3A::from_scale(cells) * to_local;
        let m = to_local.matrix3;
        // (A rotation by a right angle leaves entries of rounding size.)
        let one_per_column = |c: glam::Vec3A| {
            let big = c.abs().cmpgt(glam::Vec3A::splat(1e-5 * c.abs().max_element()));
            big.bitmask().count_ones() == 1
        };
        let aligned = one_per_column(m.x_axis) && one_per_column(m.y_axis) && one_per_column(m.z_axis);
        Majorants { res, values, to_cells, aligned, global }
    }

    /// Calls `piece(a, b, majorant)` for consecutive pieces [a, b] of
    /// `ray`'s [`t0`, `t1`] in order, each under one majorant, until it
    /// breaks.
    #[inline]
    pub fn walk(&self, ray: &Ray, t0: f32, t1: f32, mut piece: impl FnMut(f32, f32, f32) -> ControlFlow<()>) {
        let g0 = self.to_cells.transform_point3(ray.origin);
        let dg = self.to_cells.transform_vector3(ray.dir);
        let cells = Vec3::new(self.res[0] as f32, self.res[1] as f32, self.res[2] as f32);
        let (mut ta, mut tb) = (t0, t1);
        if !self.aligned {
            // The part of [t0, t1] inside the unit cube; the rest under
            // the global majorant.
            let inv = dg.recip();
            let (a, b) = (-g0 * inv, (cells - g0) * inv);
            let (near, far) = (a.min(b), a.max(b));
            ta = near.max_element().max(t0);
            tb = far.min_element().min(t1);
            if !(ta < tb) {
                let _ = piece(t0, t1, self.global);
                return;
            }
            if ta > t0 && piece(t0, ta, self.global).is_break() {
                return;
            }
        }
        if self.walk_cells(g0, dg, ta, tb, &mut piece).is_break() {
            return;
        }
        if tb < t1 {
            let _ = piece(tb, t1, self.global);
        }
    }

    /// Amanatides and Woo's traversal (1987) of the coarse cells over
    /// [`ta`, `tb`], where g(t) = `g0` + `dg` t lies in [0, res]³ up to
    /// rounding (a cell index past the grid's edge is clamped).
    #[inline]
    fn walk_cells(
        &self,
        g0: Vec3,
        dg: Vec3,
        ta: f32,
        tb: f32,
        piece: &mut impl FnMut(f32, f32, f32) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let res = self.res.map(|r| r as i32);
        let start = g0 + dg * ta;
        let mut c = [0i32; 3];
        let mut next = [f32::INFINITY; 3];
        let mut step = [f32::INFINITY; 3];
        let mut dir = [0i32; 3];
        for a in 0..3 {
            c[a] = (start[a].floor() as i32).clamp(0, res[a] - 1);
            if dg[a] > 0.0 {
                next[a] = (c[a] as f32 + 1.0 - g0[a]) / dg[a];
                (step[a], dir[a]) = (1.0 / dg[a], 1);
            } else if dg[a] < 0.0 {
                next[a] = (c[a] as f32 - g0[a]) / dg[a];
                (step[a], dir[a]) = (-1.0 / dg[a], -1);
            }
        }
        let mut t = ta;
        for _ in 0..(res[0] + res[1] + res[2] + 3) {
            let axis = if next[0] <= next[1] && next[0] <= next[2] {
                0
            } else if next[1] <= next[2] {
                1
            } else {
                2
            };
            let end = next[axis].min(tb).max(t);
            let i = ((c[2] * res[1] + c[1]) * res[0] + c[0]) as usize;
            piece(t, end, self.values[i])?;
            if !(end < tb) {
                return ControlFlow::Continue(());
            }
            t = end;
            let moved = c[axis] + dir[axis];
            if (0..res[axis]).contains(&moved) {
                c[axis] = moved;
                next[axis] += step[axis];
            } else {
                // Rounding left the grid before tb: the last cell's bound
                // holds (its fine cells' margin covers the rounding).
                next[axis] = f32::INFINITY;
            }
        }
        // Only rounding reaches here: the rest under the global majorant.
        if t < tb {
            piece(t, tb, self.global)?;
        }
        ControlFlow::Continue(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::medium::vol_file::VolGrid;
    use crate::medium::volume::{Filter, Wrap};
    use crate::sampling::{stream, Domain};
    use rand::RngExt;
    use std::sync::Arc;

    /// Along random rays through grids of falling and sparse values, under
    /// placements aligned and rotated, each filter and wrap mode: the
    /// walk's pieces follow one another from t0 to t1, and no lookup in
    /// a piece reads above its majorant, while the majorants' mean is
    /// well below the global one (they are local).
    #[test]
    fn pieces_cover_the_segment_and_bound_every_lookup() {
        let mut rng = stream(5, Domain::Camera, 0);
        let res = [24u32, 17, 40];
        // Falling along every axis (a lookup near a coarse cell's lower
        // faces reads the larger cells beyond them), with rare spikes.
        let [nx, ny, nz] = res.map(|r| r as usize);
        let data: Vec<f32> = (0..nx * ny * nz)
            .map(|i| {
                let (x, y, z) = (i % nx, i / nx % ny, i / (nx * ny));
                let ramp = ((nx - x) * (ny - y) * (nz - z)) as f32 / (nx * ny * nz) as f32;
                ramp + if rng.random::<f32>() < 0.0005 { 10.0 * rng.random::<f32>() } else { 0.0 }
            })
            .collect();
        let vol = Arc::new(VolGrid { res, channels: 1, bbox: ([0.0; 3], [1.0; 3]), data });
        let placements = [
            Affine3A::from_scale(Vec3::new(1.6, 1.6, 2.4)),
            Affine3A::from_rotation_x(90f32.to_radians()) * Affine3A::from_scale(Vec3::new(1.6, 1.6, 2.4)),
            Affine3A::from_rotation_z(0.5) * Affine3A::from_rotation_x(0.3) * Affine3A::from_scale(Vec3::splat(2.0)),
        ];
        for (k, to_world) in placements.into_iter().enumerate() {
            for (filter, wrap) in [(Filter::Trilinear, Wrap::Clamp), (Filter::Nearest, Wrap::Repeat)] {
                let grid = Grid::new(vol.clone(), to_world, false, filter, wrap).unwrap();
                let scale = 1.5;
                let global = scale * vol.max();
                let maj = Majorants::new(&grid, scale, global);
                assert_eq!(maj.aligned, k < 2, "placement {k}");
                let mean = maj.values.iter().sum::<f32>() / maj.values.len() as f32;
                assert!(mean < 0.8 * global, "placement {k}: mean majorant {mean} of {global}");
                let bbox = grid_bbox(&to_world);
                for _ in 0..2000 {
                    let o = bbox.0 + (bbox.1 - bbox.0) * Vec3::new(rng.random(), rng.random(), rng.random());
                    let d = Vec3::new(rng.random::<f32>() - 0.5, rng.random::<f32>() - 0.5, rng.random::<f32>() - 0.5);
                    let ray = Ray::new(o - 3.0 * d.normalize(), d.normalize());
                    let b = crate::medium::volume::Aabb { lo: bbox.0, hi: bbox.1 };
                    let Some((t0, t1)) = b.clip(&ray, 10.0) else { continue };
                    let mut at = t0;
                    maj.walk(&ray, t0, t1, |a, b, mu| {
                        assert!((a - at).abs() <= 1e-5 * (1.0 + at.abs()) && b >= a, "piece [{a}, {b}] after {at}");
                        at = b;
                        for i in 0..=8 {
                            let t = a + (b - a) * i as f32 / 8.0;
                            let v = grid.eval(ray.at(t)).max_element() * scale;
                            assert!(v <= mu * (1.0 + 1e-5), "placement {k}: {v} above majorant {mu} at {t}");
                        }
                        ControlFlow::Continue(())
                    });
                    assert!((at - t1).abs() <= 1e-5 * (1.0 + t1.abs()), "the pieces end at {at}, not {t1}");
                }
            }
        }
    }

    fn grid_bbox(to_world: &Affine3A) -> (Vec3, Vec3) {
        let b = crate::medium::volume::Aabb::of_unit_cube(to_world);
        (b.lo, b.hi)
    }
}
