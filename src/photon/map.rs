//! Photon maps and the density estimates read from them (Jensen 2001,
//! ch. 7): the k nearest photons within a radius cap, found through a grid
//! of cells ([`super::grid`]) or the kd-tree ([`super::kdtree`]).
//!
//! Photons are stored in Morton order so that neighbours in space are
//! neighbours in memory; the renderer's maps are then sorted by the cells
//! of a uniform grid sized for their lookups, through which most lookups go
//! instead of the tree. A map searched only at its own photons (the global
//! map) has no tree where its grid pays, and then no Morton order either:
//! its grid sorts the photons as traced.

use super::facing::FacingTrees;
use super::grid::{CellGrid, GRID_CELLS_PER_CAP, GRID_MAX_ROWS, GRID_MAX_SCAN};
use super::kdtree::{found, unpack};
use super::morton::{blocks_bounds, bounds, morton_sorted};
use super::{normal_times_127, Photon, PhotonBlocks};
use crate::math::Color;
use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;

/// Photons whose stored normal is further than this (cosine) from the query
/// normal lie on another surface (the wall in a corner, the far side of a
/// thin object) and are left out of the estimate.
pub(crate) const NORMAL_COSINE: f32 = 0.9;

/// How far behind each other's surface (as a share of their distance) a
/// photon and an estimate's point may lie and the photon still count
/// ([`in_front`]). Two points of one smooth surface whose normals differ by
/// θ lie sin(θ/2) of their distance off each other's tangent plane (on a
/// sphere exactly): 0.22 at the widest θ [`NORMAL_COSINE`] admits. Twice
/// that leaves room for shading normals tilted up to 30 degrees from the
/// surface (smooth-shaded meshes, normal maps).
const SIDE_SLOPE: f32 = 0.25;

/// Whether light a photon at `p` brought to a surface facing `m` (towards
/// the side it arrived from) can reach a point `x` on a surface facing `n`
/// (`d2`: their squared distance): each lies in front of the other's
/// surface, or behind it by no more than one smooth surface bends
/// ([`SIDE_SLOPE`]). Where either lies further behind, a surface separates
/// them: the outside of a small closed object read from its inside (the
/// photons of its far side face like its inside there), or a parallel
/// surface above or below.
#[inline]
pub(crate) fn in_front(x: Vec3, n: Vec3, p: Vec3, m: Vec3, d2: f32) -> bool {
    let d = p - x;
    // -n.d > 0: the photon lies behind x's surface; m.d > 0: x lies behind
    // the photon's.
    let behind = (-n.dot(d)).max(m.dot(d)).max(0.0);
    behind * behind <= SIDE_SLOPE * SIDE_SLOPE * d2
}

/// Scratch space a thread reuses for every query (no allocation per lookup),
/// with the squared radius its last k-nearest search needed: neighbouring
/// queries need similar radii, so the next search starts there.
#[derive(Default, Debug)]
pub struct Scratch {
    /// Photons found, as [`found`] keys: the first `found` (the vector only
    /// grows, so a search writes into it without clearing it first).
    pub(crate) buf: Vec<u64>,
    found: usize,
    /// Keys to select the k-th nearest among, leaving `buf`'s order.
    select: Vec<u64>,
    hint_r2: f32,
}

impl Scratch {
    /// Scratch whose first search starts at squared radius `r2` (searches
    /// give the same answer from any start; a fitting one is faster).
    pub fn with_hint(r2: f32) -> Self {
        Scratch { hint_r2: r2, ..Scratch::default() }
    }
}

/// A photon map: the photons, kd-trees over their positions (one per
/// facing class, [`FacingTrees`]), and, when
/// built with one, a grid of the photons' cells (`CellGrid`). A map
/// searched only at its own photons (the global map, read by the
/// irradiance cache's estimates) has the grid alone when it has one: the
/// grid then answers every search, and the tree, which cost half the map's
/// build for a few hundred searches in 300,000, is not built.
///
/// A search within radius r finds exactly the photons whose distance from
/// the query, computed from their stored positions, is at most r: the grid
/// computes that distance itself, and the tree (which sees rotated
/// positions, rounded differently) is asked a slightly wider radius and
/// its answers are tested the same way. Every estimate is therefore the
/// same whichever of the two answered it, with the grid or without.
pub struct PhotonMap {
    photons: Vec<Photon>,
    /// `None`: the grid answers every search.
    pub(crate) tree: Option<FacingTrees>,
    /// Where the trees' items (places in Morton order) are in `photons`,
    /// when the grid sorted them by cell.
    pub(crate) tree_place: Option<Vec<u32>>,
    pub(crate) grid: Option<CellGrid>,
    /// How much farther than asked the tree searches: the rotation's
    /// rounding moves a distance by far less.
    tree_pad: f32,
}

/// An irradiance estimate: flux over the disk's area pi r^2. Where the disk
/// also holds photons of another surface, part of it may lie off the
/// estimate's own surface (beyond an edge, under a contact), which then
/// holds fewer photons than its share: the estimate is low there unless its
/// area is corrected.
#[derive(Clone, Copy, Debug)]
pub struct IrradianceEstimate {
    pub irradiance: Color,
    pub r2: f32,
    /// Photons in the disk (k where the k-th set its radius; fewer where
    /// the radius cap did).
    pub count: usize,
    pub other_surfaces: bool,
}

/// The photons found for one estimate.
pub struct Gathered {
    /// Squared radius of the disk the estimate divides by.
    pub r2: f32,
    pub count: usize,
    /// Squared distance of the nearest photon of another surface met by
    /// the search (infinite if none).
    pub other_r2: f32,
}

/// What a search of the map wrote to the start of its buffer.
struct Found {
    /// How many photons.
    len: usize,
    /// Whether in index order (the grid finds them so; the tree in no set
    /// order).
    ordered: bool,
    /// Whether the map holds none within the radius cap either (known only
    /// from the grid: the search can stop growing).
    none_near: bool,
    /// Squared distance of the nearest photon of a surface facing otherwise
    /// that the search skipped (infinite if none: the grid skips none).
    other_r2: f32,
    /// Squared radius within which every photon was found (less than the
    /// radius asked where a search for the nearest few stopped at their
    /// number).
    complete_r2: f32,
}

impl PhotonMap {
    /// A map of `photons` (a pass's blocks, or one vector), searched by its
    /// kd-tree alone.
    pub fn build(photons: impl Into<PhotonBlocks>) -> Self {
        Self::build_with_grid(photons, None)
    }

    /// A map whose lookups with radius caps up to `r_cap` read a grid of
    /// cells first (`None`: the tree alone), its photons sorted by cell.
    pub fn build_with_grid(photons: impl Into<PhotonBlocks>, r_cap: Option<f32>) -> Self {
        Self::build_gridded(photons.into(), r_cap.map(|r| r / GRID_CELLS_PER_CAP), false)
    }

    /// A map searched only at its own photons (the irradiance cache's
    /// estimates), with a grid of cells `cell` wide where the photons are
    /// sparse enough for it to pay (and no tree), else the tree alone.
    pub fn build_for_photon_lookups(photons: impl Into<PhotonBlocks>, cell: f32) -> Self {
        Self::build_gridded(photons.into(), Some(cell), true)
    }

    fn build_gridded(photons: PhotonBlocks, cell: Option<f32>, at_photons: bool) -> Self {
        if let (Some(c), true) = (cell, at_photons) {
            // A map searched only through its grid needs no Morton order
            // (it served the tree, which this map does without): the grid
            // sorts the photons by cell from the order they were traced in,
            // and its cell order is the map's `spatial_order`. The
            // Morton sort was 0.39 s of the default global map's build.
            let (lo, hi) = blocks_bounds(&photons);
            let traced: Vec<Photon> = photons.blocks().concat();
            drop(photons);
            if let Some((grid, sorted, _)) = CellGrid::build(&traced, (lo, hi), c, true) {
                let reach = lo.abs().max(hi.abs()).max_element();
                return PhotonMap {
                    photons: sorted,
                    tree: None,
                    tree_place: None,
                    grid: Some(grid),
                    tree_pad: reach * 1e-5,
                };
            }
            return Self::build_gridded(PhotonBlocks::new(vec![traced]), None, false);
        }
        let morton = morton_sorted(&photons);
        drop(photons);
        // The tree is built from the Morton order (kiddo builds twice as
        // fast from spatially sorted points) while the grid sorts by cell.
        let (lo, hi) = bounds(morton.iter().map(Photon::position));
        let tree = || Some(FacingTrees::build(&morton));
        let grid = || cell.and_then(|c| CellGrid::build(&morton, (lo, hi), c, false));
        let (tree, gridded) = rayon::join(tree, grid);
        let reach = if morton.is_empty() { 0.0 } else { lo.abs().max(hi.abs()).max_element() };
        let tree_pad = reach * 1e-5;
        match gridded {
            Some((grid, photons, place)) => PhotonMap { photons, tree, tree_place: place, grid: Some(grid), tree_pad },
            None => PhotonMap { photons: morton, tree, tree_place: None, grid: None, tree_pad },
        }
    }

    /// The photon the tree knows as `item` (its place in Morton order).
    #[inline]
    fn tree_item(&self, item: u32) -> u32 {
        self.tree_place.as_ref().map_or(item, |place| place[item as usize])
    }

    /// The photons in a spatially coherent order: Morton order, or, for a
    /// map built without a tree (searched through its grid alone), the
    /// grid's cell order. A tree forced on later is built in this order.
    pub(crate) fn spatial_order(&self) -> impl IndexedParallelIterator<Item = &Photon> + '_ {
        (0..self.photons.len() as u32).into_par_iter().map(move |m| &self.photons[self.tree_item(m) as usize])
    }

    /// The same map, photons in the same order, searched by the tree alone:
    /// every estimate is the same, bit for bit (the grid is a skip of work,
    /// and this is the skip forced off).
    pub fn without_grid(mut self) -> Self {
        if self.tree.is_none() {
            let ordered: Vec<Photon> = self.spatial_order().copied().collect();
            self.tree = Some(FacingTrees::build(&ordered));
        }
        self.grid = None;
        self
    }

    /// Whether a lookup at `x` with radius cap `r_max` certainly finds no
    /// photon (answered by the grid; without one, never).
    pub fn certainly_empty(&self, x: Vec3, r_max: f32) -> bool {
        let mut rows = [(0, 0); GRID_MAX_ROWS];
        self.grid.as_ref().is_some_and(|g| g.rows(x, r_max, &mut rows).is_some_and(|(_, total)| total == 0))
    }

    pub fn len(&self) -> usize {
        self.photons.len()
    }

    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    pub fn photons(&self) -> &[Photon] {
        &self.photons
    }

    /// Bytes held by the photons, the trees (an estimate: kiddo stores one
    /// f32 triple and one u32 per point, plus its stems; each facing class
    /// one u32 per photon) and the grid.
    pub fn memory_bytes(&self) -> usize {
        self.photons.len() * (std::mem::size_of::<Photon>() + self.tree.as_ref().map_or(0, |_| 20))
            + self.grid.as_ref().map_or(0, |g| g.start.len() * 4)
            + self.tree_place.as_ref().map_or(0, |p| p.len() * 4)
    }

    /// Writes a [`found`] key for every photon within sqrt(`r2`) of `x`
    /// (see [`PhotonMap`] for what "within" means) to the start of `buf`,
    /// growing it if needed, and says what it found ([`Found`]).
    ///
    /// With `nearest > 0`, a search in the tree keeps only the `nearest`
    /// photons nearest to `x` ([`Found::complete_r2`] says where more may lie
    /// within the radius): where a caustic's focus packs thousands of
    /// photons into the disk, reading them all for each estimate was 70%
    /// of a hall scene's camera pass (a glass ball's caustic on a table).
    ///
    /// With `crowd_k > 0`, where the grid's rows hold too many photons to
    /// scan and, at their mean density, a radius well below `r2` would
    /// hold ~`crowd_k`, returns that squared radius instead (`Err`),
    /// having searched nothing: a search that comes from a sparse region
    /// with a wide radius into the caustic's focus would otherwise read
    /// thousands of photons from the tree for one estimate.
    fn within(
        &self,
        x: Vec3,
        r2: f32,
        r_max: f32,
        n: Vec3,
        buf: &mut Vec<u64>,
        (crowd_k, nearest): (usize, usize),
    ) -> Result<Found, f32> {
        let mut rows = [(0, 0); GRID_MAX_ROWS];
        let r = r2.sqrt();
        if let Some(grid) = &self.grid {
            let listed = grid.rows(x, r, &mut rows);
            let grid_only = self.tree.is_none();
            if let (Some((_, total)), false) = (listed, grid_only) {
                if total > GRID_MAX_SCAN && crowd_k > 0 {
                    if let Some(smaller) = grid.crowded_radius2(x, r, total, crowd_k).filter(|&s| s < 0.5 * r2) {
                        return Err(smaller.max(r2 / 64.0));
                    }
                }
            }
            if grid_only || listed.is_some_and(|(_, total)| total <= GRID_MAX_SCAN) {
                let mut len = 0;
                match listed {
                    Some((n, _)) => {
                        for &(s, e) in &rows[..n] {
                            len = self.scan(x, r2, s, e, buf, len);
                        }
                    }
                    // Too many rows to list (a grid-only map's search at a
                    // radius far above its cells): read them as they come.
                    None => {
                        if let Some(cells) = grid.cell_box(x, r) {
                            grid.each_row(cells, |s, e| len = self.scan(x, r2, s, e, buf, len));
                        }
                    }
                }
                let none_near =
                    len == 0 && (r >= r_max || !x.is_finite() || grid.rows(x, r_max, &mut rows) == Some((0, 0)));
                return Ok(Found { len, ordered: true, none_near, other_r2: f32::INFINITY, complete_r2: r2 });
            }
        }
        let Some(tree) = &self.tree else {
            return Ok(Found { len: 0, ordered: false, none_near: true, other_r2: f32::INFINITY, complete_r2: r2 });
        };
        let wide = r + self.tree_pad + r * 1e-4;
        let mut len = 0;
        let keep = |item: u32| {
            let i = self.tree_item(item);
            let d2 = self.photons[i as usize].position().distance_squared(x);
            if d2 <= r2 {
                if len < buf.len() {
                    buf[len] = found(d2, i);
                } else {
                    buf.push(found(d2, i));
                }
                len += 1;
            }
        };
        let (other_r2, complete_r2) = if nearest > 0 {
            let (other, complete) = tree.visit_nearest(x, wide * wide, n, nearest, keep);
            // The tree's distances are the rotated positions': shrink the
            // radius known complete by the padding.
            let complete =
                if complete >= wide * wide { r2 } else { (complete.sqrt() - self.tree_pad).max(0.0).powi(2) };
            (other, complete)
        } else {
            (tree.visit(x, wide * wide, n, keep), r2)
        };
        Ok(Found { len, ordered: false, none_near: false, other_r2, complete_r2 })
    }

    /// Writes a [`found`] key for each photon of `s..e` within sqrt(`r2`)
    /// of `x` to `buf[len..]`, growing `buf` if needed, and returns the new
    /// length. Every candidate is written and the count advanced only for
    /// those inside: many are not, and a branch on it would be mispredicted
    /// often.
    #[inline]
    fn scan(&self, x: Vec3, r2: f32, s: u32, e: u32, buf: &mut Vec<u64>, mut len: usize) -> usize {
        let need = len + (e - s) as usize;
        if buf.len() < need {
            buf.resize(need, 0);
        }
        for (i, p) in (s..e).zip(&self.photons[s as usize..e as usize]) {
            let d2 = p.position().distance_squared(x);
            buf[len] = found(d2, i);
            len += (d2 <= r2) as usize;
        }
        len
    }

    /// Finds the `k` nearest photons within `r_max` of `x` (fewer if fewer are
    /// there) on a surface facing like `n`, and leaves them in the scratch
    /// in index order; the estimates sum them in that order, which does not
    /// depend on the radius searched (hence not on the thread's previous
    /// query) nor on whether the grid or the tree found them. The
    /// estimate's disk has the k-th photon on its rim, or radius `r_max`
    /// when fewer than `k` were found (a fixed-radius estimate).
    ///
    /// Photons on other surfaces (a wall in a corner, the far side of a
    /// thin wall) do not count towards k: where they outnumber the
    /// surface's own by orders of magnitude (a sunlit outside wall behind
    /// a room's wall), counting them shrank the disk until the room's side
    /// had no photon in most estimates. Where they lie inside the disk the
    /// estimate says so ([`Gathered::other_r2`]), for the coverage
    /// correction.
    ///
    /// With `sided`, only photons in front of `x`'s surface, and `x` in
    /// front of theirs ([`in_front`]), count. The irradiance estimate asks
    /// that of the photons it found unsided as it adds them up
    /// ([`Self::behind`]) and gathers again, sided, only where one fails
    /// (nearly nowhere): asking it of each photon found, on every round of
    /// a growing search, cost several percent of the default command.
    #[inline(always)]
    fn gather(&self, sided: bool, x: Vec3, n: Vec3, k: usize, r_max: f32, scratch: &mut Scratch) -> Gathered {
        let r_max2 = r_max * r_max;
        let Scratch { buf, select, .. } = scratch;
        // Search a growing radius from the hint: the k nearest within the
        // radius are the k nearest, whatever radius found them, so the
        // result is that of one search at r_max, at the cost of the
        // photons near the answer only.
        let mut r2 = if k > 0 && scratch.hint_r2 > 0.0 { scratch.hint_r2.min(r_max2) } else { r_max2 };
        let (mut count, mut ordered);
        let mut other_r2 = f32::INFINITY;
        // The radius is narrowed at most once (see `within`); from there
        // it only grows, so the loop ends.
        let mut may_narrow = k > 0;
        // The tree is asked for a few more than the k nearest: the k nearest
        // facing like `n` are among them wherever at least k of them face
        // so (away from edges, all do) and lie where the search was
        // complete; else it is repeated for four times as many, and from
        // 65,536 for all.
        let mut nearest = k + k / 2;
        let more = |nearest: usize| if nearest == 0 || nearest >= 1 << 16 { 0 } else { 4 * nearest };
        let r2 = loop {
            let found = match self.within(x, r2, r_max, n, buf, (if may_narrow { k } else { 0 }, nearest)) {
                Ok(found) => found,
                Err(narrower) => {
                    (r2, may_narrow) = (narrower, false);
                    continue;
                }
            };
            (count, ordered) = (found.len, found.ordered);
            other_r2 = other_r2.min(found.other_r2);
            let mut kept = 0;
            for j in 0..count {
                let key = buf[j];
                let (d2, i) = unpack(key);
                if if sided { self.reads(i, x, n, d2) } else { self.faces(i, n) } {
                    buf[kept] = key;
                    kept += 1;
                } else {
                    other_r2 = other_r2.min(d2);
                }
            }
            count = kept;
            if k > 0 && count >= k {
                // Keys rank photons at equal distances (f32 squares do tie,
                // a few times per million estimates) by index: the k-th key
                // and those below it are the k nearest, selected in a copy
                // and kept in place, in their order, without a branch on each.
                select.clear();
                select.extend_from_slice(&buf[..count]);
                let kth = *select.select_nth_unstable(k - 1).1;
                if unpack(kth).0 > found.complete_r2 {
                    // A nearer photon may have been left out.
                    nearest = more(nearest);
                    continue;
                }
                let mut kept = 0;
                for j in 0..count {
                    let key = buf[j];
                    buf[kept] = key;
                    kept += (key <= kth) as usize;
                }
                count = kept;
                break unpack(kth).0;
            }
            if found.complete_r2 < r2 {
                nearest = more(nearest);
                continue;
            }
            if r2 >= r_max2 || found.none_near {
                break r_max2;
            }
            // Photons lie on surfaces, so their count grows with r^2: aim at
            // k with a margin, by at most 4x the area.
            let grow = (1.3 * k as f32 / count.max(1) as f32).clamp(1.5, 4.0);
            r2 = (r2 * grow).min(r_max2);
        };
        if !ordered {
            buf[..count].sort_unstable_by_key(|&key| key as u32);
        }
        scratch.found = count;
        scratch.hint_r2 = if r2 < r_max2 { r2 * 1.25 } else { r_max2 };
        Gathered { r2, count, other_r2 }
    }

    /// Whether photon `i` lies on a surface facing like `n`.
    #[inline]
    fn faces(&self, i: u32, n: Vec3) -> bool {
        normal_times_127(self.photons[i as usize].normal).dot(n) >= 127.0 * NORMAL_COSINE
    }

    /// Whether photon `i` (at squared distance `d2` from `x`) lies on
    /// `x`'s surface, which faces `n`: on a surface facing like it, and
    /// not behind it nor it behind the photon's ([`in_front`]).
    #[inline]
    fn reads(&self, i: u32, x: Vec3, n: Vec3, d2: f32) -> bool {
        self.faces(i, n) && !self.behind(&self.photons[i as usize], x, 127.0 * n, d2)
    }

    /// Whether `photon` (at squared distance `d2` from `x`) and `x`, on a
    /// surface facing `n127` (its normal times 127), lie behind each
    /// other's surface ([`in_front`]).
    #[inline(always)]
    fn behind(&self, photon: &Photon, x: Vec3, n127: Vec3, d2: f32) -> bool {
        // Both normals 127 times as long, the distance too ([`in_front`]
        // asks for ratios): no division for the stored normal's unit.
        !in_front(x, n127, photon.position(), normal_times_127(photon.normal), 127.0 * 127.0 * d2)
    }

    /// Irradiance at `x` with a box kernel: sum of flux / (pi r^2). When the
    /// radius was set by the k-th photon, that photon (on the rim) is left
    /// out: for a uniform density the k-1 photons strictly inside the disk
    /// give an unbiased estimate, all k would overestimate by k / (k - 1).
    pub fn irradiance(&self, x: Vec3, n: Vec3, k: usize, r_max: f32, buf: &mut Scratch) -> (Color, f32) {
        let e = self.irradiance_estimate(x, n, k, r_max, buf);
        (e.irradiance, e.r2)
    }

    /// [`Self::irradiance`], and whether the disk held photons of another
    /// surface: an edge, a corner or a contact is within it, and part of
    /// the disk may lie off the surface (see [`IrradianceEstimate`]).
    pub fn irradiance_estimate(&self, x: Vec3, n: Vec3, k: usize, r_max: f32, buf: &mut Scratch) -> IrradianceEstimate {
        let (mut sided, n127) = (false, 127.0 * n);
        let (g, flux) = loop {
            let g = self.gather(sided, x, n, k, r_max, buf);
            if g.count == 0 || !(g.r2 > 0.0) {
                return IrradianceEstimate { irradiance: Color::ZERO, r2: g.r2, count: 0, other_surfaces: false };
            }
            let on_rim_excluded = g.r2 < r_max * r_max;
            let (mut flux, mut behind) = (Color::ZERO, false);
            for (d2, i) in buf.buf[..buf.found].iter().map(|&key| unpack(key)) {
                let photon = &self.photons[i as usize];
                behind |= !sided && self.behind(photon, x, n127, d2);
                if !on_rim_excluded || d2 < g.r2 {
                    flux += photon.flux();
                }
            }
            if !behind {
                break (g, flux);
            }
            sided = true;
        };
        let on_rim_excluded = g.r2 < r_max * r_max;
        let other_surfaces = if on_rim_excluded { g.other_r2 < g.r2 } else { g.other_r2 <= g.r2 };
        IrradianceEstimate { irradiance: flux / (PI * g.r2), r2: g.r2, count: g.count, other_surfaces }
    }

    /// Radiance reflected by a Lambertian surface of reflectance `rho`,
    /// estimated with Jensen's cone filter (k = 1: weight 1 - d / r,
    /// normalised by 1 / (1 - 2/3)), which keeps caustic edges sharp.
    pub fn radiance_cone(&self, x: Vec3, n: Vec3, rho: Color, k: usize, r_max: f32, buf: &mut Scratch) -> Color {
        self.cone_estimate(x, n, k, r_max, buf).radiance(rho)
    }

    /// The photons' share of [`Self::radiance_cone`], which any reflectance
    /// turns into radiance.
    pub fn cone_estimate(&self, x: Vec3, n: Vec3, k: usize, r_max: f32, buf: &mut Scratch) -> ConeEstimate {
        // Not sided: the camera pass makes one at nearly every diffuse hit
        // and the side test cost 3% of the default command there, while the
        // caustic map's radius cap is a tenth of the global map's (a closed
        // object smaller than it is smaller than most caustics' detail).
        let g = self.gather(false, x, n, k, r_max, buf);
        if g.count == 0 || !(g.r2 > 0.0) {
            return ConeEstimate { weighted_flux: Color::ZERO, r2: g.r2 };
        }
        let inv_r = 1.0 / g.r2.sqrt();
        let mut weighted_flux = Color::ZERO;
        for (d2, i) in buf.buf[..buf.found].iter().map(|&key| unpack(key)) {
            weighted_flux += self.photons[i as usize].flux() * (1.0 - d2.sqrt() * inv_r).max(0.0);
        }
        ConeEstimate { weighted_flux, r2: g.r2 }
    }
}

/// A cone-filtered estimate: the photons' flux times their cone weights,
/// and the squared radius of the disk.
#[derive(Clone, Copy, Debug)]
pub struct ConeEstimate {
    pub weighted_flux: Color,
    pub r2: f32,
}

impl ConeEstimate {
    /// Radiance reflected by a Lambertian surface of reflectance `rho`.
    pub fn radiance(&self, rho: Color) -> Color {
        if !(self.r2 > 0.0) {
            return Color::ZERO;
        }
        rho / PI * self.weighted_flux * 3.0 / (PI * self.r2)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::photon::grid::GRID_MAX_CELLS;

    use crate::sampling::{next_2d, stream, Domain};

    /// Photons of equal power spread uniformly over a square: the estimates
    /// must return the known irradiance (and radiance rho/pi * E).
    #[test]
    fn estimates_recover_a_uniform_photon_density() {
        let mut rng = stream(11, Domain::Camera, 0);
        let (side, n) = (10.0f32, 400_000usize);
        let power = 2.0f32;
        let photons: Vec<Photon> = (0..n)
            .map(|_| {
                let u = next_2d(&mut rng) * side;
                Photon::new(Vec3::new(u.x, u.y, 0.0), Color::splat(power), Vec3::Z)
            })
            .collect();
        let map = PhotonMap::build(photons);
        let exact = power * n as f32 / (side * side);
        let mut buf = Scratch::default();
        let mut box_sum = 0.0;
        let mut cone_sum = 0.0;
        let queries = 400;
        for q in 0..queries {
            let x = Vec3::new(2.0 + 6.0 * (q % 20) as f32 / 20.0, 2.0 + 6.0 * (q / 20) as f32 / 20.0, 0.0);
            box_sum += map.irradiance(x, Vec3::Z, 200, 1.0, &mut buf).0.x;
            cone_sum += map.radiance_cone(x, Vec3::Z, Color::splat(PI), 200, 1.0, &mut buf).x;
        }
        let (box_mean, cone_mean) = (box_sum / queries as f32, cone_sum / queries as f32);
        // Both estimators leave out the rim photon and are unbiased for a
        // uniform density: means within 1% of the truth over 400 queries.
        assert!((box_mean / exact - 1.0).abs() < 0.01, "box {box_mean} vs {exact}");
        assert!((cone_mean / exact - 1.0).abs() < 0.01, "cone {cone_mean} vs {exact}");
        // With few photons per estimate the rim photon matters most: k = 3
        // would overestimate by 50% if it were counted.
        let mut small = 0.0;
        for q in 0..queries {
            let x = Vec3::new(2.0 + 6.0 * (q % 20) as f32 / 20.0, 2.0 + 6.0 * (q / 20) as f32 / 20.0, 0.0);
            small += map.irradiance(x, Vec3::Z, 3, 1.0, &mut buf).0.x;
        }
        let small_mean = small / queries as f32;
        assert!((small_mean / exact - 1.0).abs() < 0.15, "k = 3: {small_mean} vs {exact}");
        // Photons facing away (other surface) are ignored.
        assert_eq!(map.irradiance(Vec3::new(5.0, 5.0, 0.0), -Vec3::Z, 50, 1.0, &mut buf).0, Color::ZERO);
        // An empty map answers zero.
        let empty = PhotonMap::build(Vec::new());
        assert_eq!(empty.irradiance(Vec3::ZERO, Vec3::Z, 10, 1.0, &mut buf).0, Color::ZERO);
    }

    /// Estimates start their search from the radius the thread's previous
    /// query needed; the answer must not depend on that history: the same
    /// bits with a fresh scratch per query, and along the path either way.
    #[test]
    fn estimates_do_not_depend_on_the_previous_query() {
        let mut rng = stream(14, Domain::Camera, 0);
        // A floor with a denser stripe, and a wall: radii vary along the path.
        let photons: Vec<Photon> = (0..60_000)
            .map(|i| {
                let u = next_2d(&mut rng) * 4.0;
                match i % 3 {
                    0 => Photon::new(Vec3::new(u.x, 0.0, u.y), Color::ONE, Vec3::Y),
                    1 => Photon::new(Vec3::new(1.5 + u.x / 8.0, 0.0, u.y), Color::splat(2.0), Vec3::Y),
                    _ => Photon::new(Vec3::new(0.0, u.x, u.y), Color::splat(0.5), Vec3::X),
                }
            })
            .collect();
        let map = PhotonMap::build(photons);
        let path: Vec<Vec3> =
            (0..300).map(|i| Vec3::new(0.01 * i as f32 + 0.001, 0.0, 2.0 + 0.003 * i as f32)).collect();
        let estimate = |x: Vec3, s: &mut Scratch| {
            let cone = map.radiance_cone(x, Vec3::Y, Color::ONE, 50, 0.1, s);
            let (e, r2) = map.irradiance(x, Vec3::Y, 80, 0.1, s);
            (cone.to_array(), e.to_array(), r2)
        };
        let fresh: Vec<_> = path.iter().map(|&x| estimate(x, &mut Scratch::default())).collect();
        let mut s = Scratch::default();
        let forward: Vec<_> = path.iter().map(|&x| estimate(x, &mut s)).collect();
        let mut backward: Vec<_> = path.iter().rev().map(|&x| estimate(x, &mut s)).collect();
        backward.reverse();
        assert_eq!(forward, fresh);
        assert_eq!(backward, fresh);
        // Some estimates found fewer than k within the cap, some more.
        assert!(fresh.iter().any(|f| f.2 < 0.1 * 0.1) && fresh.iter().any(|f| f.2 == 0.1f32 * 0.1));
    }

    /// The cone estimate of `map` at `x` (normal +y) from a sort of all its
    /// photons by distance.
    fn brute_cone(map: &PhotonMap, x: Vec3, n: Vec3, k: usize, r_max: f32) -> (Color, f32) {
        let mut keys: Vec<u64> = (0..map.len() as u32)
            .filter(|&i| map.faces(i, n))
            .map(|i| found(map.photons()[i as usize].position().distance_squared(x), i))
            .filter(|&key| unpack(key).0 <= r_max * r_max)
            .collect();
        keys.sort_unstable();
        let r2 = if k > 0 && keys.len() >= k { unpack(keys[k - 1]).0 } else { r_max * r_max };
        if k > 0 {
            keys.truncate(k);
        }
        keys.sort_unstable_by_key(|&key| key as u32);
        if keys.is_empty() || !(r2 > 0.0) {
            return (Color::ZERO, r2);
        }
        let inv_r = 1.0 / r2.sqrt();
        let mut sum = Color::ZERO;
        for (d2, i) in keys.iter().map(|&key| unpack(key)) {
            sum += map.photons()[i as usize].flux() * (1.0 - d2.sqrt() * inv_r).max(0.0);
        }
        (sum, r2)
    }

    /// Asserts that both maps' cone estimates along `path`, forwards and
    /// backwards with one scratch, equal the brute force's bits; returns
    /// those.
    fn same_as_brute_force(
        grid: &PhotonMap,
        tree: &PhotonMap,
        path: &[Vec3],
        n: Vec3,
        k: usize,
        r_max: f32,
    ) -> Vec<(Color, f32)> {
        let expected: Vec<(Color, f32)> = path.iter().map(|&x| brute_cone(grid, x, n, k, r_max)).collect();
        let run = |map: &PhotonMap, order: &mut dyn Iterator<Item = usize>| {
            let mut out = vec![(Color::ZERO, 0.0); path.len()];
            let mut s = Scratch::default();
            for i in order {
                let e = map.cone_estimate(path[i], n, k, r_max, &mut s);
                out[i] = (e.weighted_flux, e.r2);
            }
            out
        };
        for map in [grid, tree] {
            assert_eq!(run(map, &mut (0..path.len())), expected);
            assert_eq!(run(map, &mut (0..path.len()).rev()), expected);
        }
        expected
    }

    /// Layouts that stress the grid: every photon at one point, a single
    /// photon, a floor so wide that the grid's cells are coarsened far past
    /// the radius (every search goes to the tree), and photons far from the
    /// origin, where a coordinate's last bit is a millimetre.
    #[test]
    fn grid_searches_equal_brute_force_on_degenerate_layouts() {
        let mut rng = stream(17, Domain::Camera, 0);
        let floor = |n: usize, origin: Vec3, side: f32, rng: &mut _| -> Vec<Photon> {
            (0..n)
                .map(|_| {
                    let u = next_2d(rng);
                    Photon::new(origin + Vec3::new(side * u.x, 0.0, side * u.y), Color::ONE, Vec3::Y)
                })
                .collect()
        };
        let at = Vec3::new(1.0, 2.0, 3.0);
        let cases: Vec<(&str, Vec<Photon>, Vec3, f32)> = vec![
            ("one point", vec![Photon::new(at, Color::ONE, Vec3::Y); 500], at, 0.1),
            ("one photon", vec![Photon::new(at, Color::ONE, Vec3::Y)], at, 0.1),
            ("wide floor", floor(20_000, Vec3::ZERO, 1e5, &mut rng), Vec3::new(5e4, 0.0, 5e4), 1e-2),
            (
                "far floor",
                floor(20_000, Vec3::new(3e4, -2e4, 1e4), 4.0, &mut rng),
                Vec3::new(3e4 + 2.0, -2e4, 1e4 + 2.0),
                0.2,
            ),
        ];
        for (name, photons, centre, r_max) in cases {
            let grid = PhotonMap::build_with_grid(photons.clone(), Some(r_max));
            let cells = grid.grid.as_ref().map_or(0, |g| g.start.len());
            assert!(cells <= GRID_MAX_CELLS as usize + 1, "{name}: {cells} cells");
            let tree = PhotonMap::build_with_grid(photons, Some(r_max)).without_grid();
            let path: Vec<Vec3> = (0..40)
                .map(|i| centre + Vec3::new(0.013 * r_max * (i as f32 - 20.0), 0.0, 0.007 * r_max * i as f32))
                .collect();
            for k in [0, 1, 20] {
                let e = same_as_brute_force(&grid, &tree, &path, Vec3::Y, k, r_max);
                assert!(e.iter().all(|(c, r2)| c.is_finite() && r2.is_finite()), "{name}");
            }
        }
    }

    /// The grid's rows, the tree, and the two mixed (the tree answers where
    /// rows hold too many photons, at a radius first narrowed to their
    /// density when the search comes in wide) find exactly the k nearest that a brute
    /// force over every photon finds, in any query order, and the estimates
    /// sum them in the same order: the same bits.
    #[test]
    fn grid_and_tree_estimates_equal_brute_force() {
        let mut rng = stream(15, Domain::Camera, 0);
        // A sparse floor, a focus 400x denser on it, and a wall meeting it.
        let photons: Vec<Photon> = (0..60_000)
            .map(|i| {
                let u = next_2d(&mut rng);
                match i % 3 {
                    0 => Photon::new(Vec3::new(4.0 * u.x, 0.0, 4.0 * u.y), Color::ONE, Vec3::Y),
                    1 => Photon::new(Vec3::new(2.0 + 0.2 * u.x, 0.0, 2.0 + 0.2 * u.y), Color::splat(0.3), Vec3::Y),
                    _ => Photon::new(Vec3::new(0.0, 4.0 * u.x, 4.0 * u.y), Color::splat(0.5), Vec3::X),
                }
            })
            .collect();
        let (k, r_max) = (50, 0.08);
        let grid = PhotonMap::build_with_grid(photons.clone(), Some(r_max));
        let tree = PhotonMap::build_with_grid(photons, Some(r_max)).without_grid();
        assert!(grid.grid.is_some() && tree.grid.is_none());
        // From the wall across the sparse floor into the focus and out.
        let path: Vec<Vec3> =
            (0..400).map(|i| Vec3::new(0.0001 + 0.006 * i as f32, 0.0, 0.5 + 0.0045 * i as f32)).collect();
        let expected = same_as_brute_force(&grid, &tree, &path, Vec3::Y, k, r_max);
        // The path needed both the grid's rows and, in the focus, the tree.
        let scanned = |&(x, (_, r2)): &(&Vec3, &(Color, f32))| {
            grid.grid.as_ref().unwrap().rows(*x, r2.sqrt(), &mut [(0, 0); GRID_MAX_ROWS]).map(|(_, total)| total)
        };
        let totals: Vec<_> = path.iter().zip(&expected).map(|e| scanned(&e)).collect();
        assert!(totals.iter().any(|t| t.is_some_and(|t| t > GRID_MAX_SCAN)), "no lookup went to the tree");
        assert!(totals.iter().filter(|t| t.is_some_and(|t| t <= GRID_MAX_SCAN)).count() > 100);
        assert!(expected.iter().any(|e| e.1 < r_max * r_max) && expected.iter().any(|e| e.1 == r_max * r_max));
    }

    /// A search on one surface beside another's focus (the front face of a
    /// table under the caustic on its top, and a chamfer between them):
    /// the facing classes' trees and their nearest-few searches find what
    /// a brute force over every photon finds, on each surface, and the
    /// estimate knows the other surfaces are inside its disk.
    #[test]
    fn searches_beside_another_surfaces_focus_equal_brute_force() {
        let mut rng = stream(16, Domain::Camera, 0);
        let chamfer = Vec3::new(0.0, -1.0, 1.0).normalize();
        let photons: Vec<Photon> = (0..120_000)
            .map(|i| {
                let u = next_2d(&mut rng);
                match i % 6 {
                    // The top (z = 0, facing +z): a focus packed at its edge.
                    0..=3 => Photon::new(Vec3::new(2.0 + 0.3 * u.x, 0.01 + 0.3 * u.y * u.y, 0.0), Color::ONE, Vec3::Z),
                    // The front face (y = 0, facing -y), sparse.
                    4 => Photon::new(Vec3::new(4.0 * u.x, 0.0, -4.0 * u.y), Color::splat(3.0), -Vec3::Y),
                    // A chamfer along the edge, facing between the two.
                    _ => Photon::new(Vec3::new(4.0 * u.x, -0.01 * u.y, -0.01 + 0.01 * u.y), Color::splat(2.0), chamfer),
                }
            })
            .collect();
        let r_max = 0.2;
        let grid = PhotonMap::build_with_grid(photons.clone(), Some(r_max));
        let tree = PhotonMap::build_with_grid(photons, Some(r_max)).without_grid();
        let across = |y: f32, z: f32| -> Vec<Vec3> {
            (0..60).map(|i| Vec3::new(1.8 + 0.012 * i as f32, y, z - 0.002 * (i % 7) as f32)).collect()
        };
        for (surface, path, n) in [
            ("front", across(0.0, -0.02), -Vec3::Y),
            ("chamfer", across(-0.005, -0.005), chamfer),
            ("top", across(0.02, 0.0), Vec3::Z),
        ] {
            for k in [1, 50] {
                let e = same_as_brute_force(&grid, &tree, &path, n, k, r_max);
                assert!(e.iter().any(|(c, _)| c.x > 0.0), "{surface}: found nothing");
            }
            // Whether another surface lies in the disk, as a brute force
            // over the photons facing otherwise tells.
            let mut s = Scratch::default();
            let mut beside = 0;
            for &x in &path {
                let e = tree.irradiance_estimate(x, n, 50, r_max, &mut s);
                let other = (0..tree.len() as u32)
                    .filter(|&i| !tree.reads(i, x, n, tree.photons()[i as usize].position().distance_squared(x)))
                    .map(|i| tree.photons()[i as usize].position().distance_squared(x))
                    .fold(f32::INFINITY, f32::min);
                // (An estimate that found no photon of its own says nothing.)
                let inside = if e.r2 < r_max * r_max { other < e.r2 } else { other <= e.r2 };
                assert_eq!(e.other_surfaces, inside && e.irradiance != Color::ZERO, "{surface} at {x}");
                assert_eq!(grid.irradiance_estimate(x, n, 50, r_max, &mut s).other_surfaces, e.other_surfaces);
                beside += e.other_surfaces as usize;
            }
            assert!(beside > 0, "{surface}: no estimate saw the other surfaces");
        }
    }

    /// `n` photons of total power 1 spread uniformly over the outside of
    /// the unit sphere (each facing outwards, where it arrived from).
    pub(crate) fn sphere_outside(seed: u64, n: usize) -> Vec<Photon> {
        let mut rng = stream(seed, Domain::Camera, 0);
        (0..n)
            .map(|_| {
                let d = crate::sampling::uniform_cone(next_2d(&mut rng), -1.0).normalize();
                Photon::new(d, Color::splat(1.0 / n as f32), d)
            })
            .collect()
    }

    /// Photons on the outside of a unit sphere, read from its inside (the
    /// normal turned inwards) with a radius cap beyond its diameter: none
    /// counts (the far side's face like the inside there; they counted
    /// before estimates asked which side of each other's surface photon
    /// and point lie). Read from the outside, the estimates find their
    /// density (the sphere curving away within the disk).
    #[test]
    fn estimates_do_not_read_through_a_closed_surface() {
        let map = PhotonMap::build(sphere_outside(8, 40_000));
        let mut s = Scratch::default();
        let mut rng = stream(9, Domain::Camera, 0);
        let mut outside = 0.0;
        let points = 200;
        for _ in 0..points {
            let d = crate::sampling::uniform_cone(next_2d(&mut rng), -1.0).normalize();
            for k in [1, 100] {
                let inside = map.irradiance_estimate(d, -d, k, 3.0, &mut s);
                assert_eq!(inside.irradiance, Color::ZERO, "at {d}, k {k}: {inside:?}");
            }
            outside += map.irradiance(d, d, 100, 3.0, &mut s).0.x as f64;
        }
        // Irradiance 1 / 4π; each estimate within ~10%.
        let mean = outside / points as f64 * 4.0 * std::f64::consts::PI;
        assert!((mean - 1.0).abs() < 0.03, "outside: {mean} of the density");
    }

    /// `n` photons of power 1 spread uniformly over the square [0, 4]^2 of
    /// the plane y = 0, facing +y (random stream `seed`).
    pub(crate) fn uniform_floor(seed: u64, n: usize) -> Vec<Photon> {
        let mut rng = stream(seed, Domain::Camera, 0);
        (0..n)
            .map(|_| {
                let u = next_2d(&mut rng) * 4.0;
                Photon::new(Vec3::new(u.x, 0.0, u.y), Color::ONE, Vec3::Y)
            })
            .collect()
    }

    /// A map searched at its photons keeps its grid only where a photon's
    /// cell and its neighbours hold few enough to scan, and then has no
    /// tree: the grid answers every search, also those with more rows or
    /// photons than a map with a tree would read from it.
    #[test]
    fn photon_lookup_maps_keep_a_grid_only_where_it_pays() {
        let photons = uniform_floor(19, 50_000);
        // ~8 photons per 5 cm cell: kept. ~3,000 per 1 m cell: dropped.
        let fine = PhotonMap::build_for_photon_lookups(photons.clone(), 0.05);
        let coarse = PhotonMap::build_for_photon_lookups(photons.clone(), 1.0);
        assert!(fine.grid.is_some() && fine.tree.is_none());
        assert!(coarse.grid.is_none() && coarse.tree.is_some());
        // The tree is built when the grid is forced off.
        let fine_tree = PhotonMap::build_for_photon_lookups(photons, 0.05).without_grid();
        assert!(fine_tree.tree.is_some());
        // The path leaves the floor's photons; at the 2.0 cap a search
        // spans 81 x 81 rows and ~40,000 photons.
        let path: Vec<Vec3> = (0..30).map(|i| Vec3::new(0.2 * i as f32 + 0.5, 0.0, 2.0)).collect();
        let mut rows = [(0, 0); GRID_MAX_ROWS];
        assert!(fine.grid.as_ref().unwrap().rows(path[5], 2.0, &mut rows).is_none());
        for (k, r_max) in [(30, 0.5), (3000, 0.5), (30, 2.0), (20_000, 2.0)] {
            same_as_brute_force(&fine, &fine_tree, &path, Vec3::Y, k, r_max);
            same_as_brute_force(&coarse, &coarse, &path, Vec3::Y, k, r_max);
        }
        // Far from every photon, and at a point that is not one: nothing.
        let mut s = Scratch::default();
        for x in [Vec3::splat(50.0), Vec3::splat(f32::NAN)] {
            assert_eq!(fine.irradiance(x, Vec3::Y, 30, 0.5, &mut s).0, Color::ZERO);
        }
    }
}
