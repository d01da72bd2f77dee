//! Volumes: a medium's coefficients as functions of position, as Mitsuba 3
//! defines its `constvolume` and `gridvolume` plugins (src/volumes/):
//! each has a `to_world` transform placing its unit cube [0, 1]^3 in the
//! scene; the cube's world bounds are where a heterogeneous medium's
//! density lives (Mitsuba's `Volume::bbox`). A grid is looked up in the
//! cube, trilinearly between cell centres or at the nearest cell, and
//! outside [0, 1] by its wrap mode (clamp, repeat, mirror).

use super::vol_file::VolGrid;
use crate::math::{Color, Ray};
use glam::{Affine3A, Vec3};
use std::ops::{Add, AddAssign, Mul, Sub};
use std::sync::Arc;

/// How a grid is read between its cells (Mitsuba's `filter_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    Trilinear,
    Nearest,
}

/// How a grid is read outside [0, 1]^3 (Mitsuba's `wrap_mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Clamp,
    Repeat,
    Mirror,
}

impl Filter {
    pub fn name(self) -> &'static str {
        match self {
            Filter::Trilinear => "trilinear",
            Filter::Nearest => "nearest",
        }
    }
}

impl Wrap {
    pub fn name(self) -> &'static str {
        match self {
            Wrap::Clamp => "clamp",
            Wrap::Repeat => "repeat",
            Wrap::Mirror => "mirror",
        }
    }
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub lo: Vec3,
    pub hi: Vec3,
}

impl Aabb {
    /// The world bounds of the unit cube under `to_world`.
    pub fn of_unit_cube(to_world: &Affine3A) -> Aabb {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for i in 0..8 {
            let c = Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32);
            let p = to_world.transform_point3(c);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        Aabb { lo, hi }
    }

    /// The part [t0, t1] of the ray's [0, t_max] inside the box (slab
    /// test), `None` where the ray misses it.
    #[inline]
    pub fn clip(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        self.clip_inv(ray.origin, ray.dir.recip(), t_max)
    }

    /// Whether a ray from `origin` with reciprocal direction `inv` crosses
    /// the box within [0, `t_max`] ([`Self::clip`], the division hoisted
    /// out of a traversal's many boxes).
    #[inline]
    pub fn crossed(&self, origin: Vec3, inv: Vec3, t_max: f32) -> bool {
        self.clip_inv(origin, inv, t_max).is_some()
    }

    #[inline]
    fn clip_inv(&self, origin: Vec3, inv: Vec3, t_max: f32) -> Option<(f32, f32)> {
        let a = (self.lo - origin) * inv;
        let b = (self.hi - origin) * inv;
        // NaN (0 * inf, a ray in a slab's plane) loses against any number
        // in min / max, so such an axis cuts nothing.
        let near = a.min(b);
        let far = a.max(b);
        let t0 = near.x.max(near.y).max(near.z).max(0.0);
        let t1 = far.x.min(far.y).min(far.z).min(t_max);
        (t0 <= t1).then_some((t0, t1))
    }
}

/// A grid of values placed in the scene.
#[derive(Clone, Debug)]
pub struct Grid {
    pub data: Arc<VolGrid>,
    /// As the scene gave it (before `use_grid_bbox`).
    pub to_world: Affine3A,
    pub use_grid_bbox: bool,
    pub filter: Filter,
    pub wrap: Wrap,
    /// World to the grid's unit cube.
    to_local: Affine3A,
    bbox: Aabb,
}

/// A function of position (Mitsuba's `Volume`).
#[derive(Clone, Debug)]
pub enum Volume {
    /// One value everywhere; its unit cube still bounds a heterogeneous
    /// medium whose extinction it is (Mitsuba's `constvolume`).
    Constant {
        value: Color,
        to_world: Affine3A,
    },
    Grid(Grid),
}

impl Grid {
    /// A grid under `to_world`; with `use_grid_bbox` the file's box is
    /// mapped to the unit cube first (Mitsuba's `bbox_transform`). `None`
    /// where either transform is singular.
    pub fn new(
        data: Arc<VolGrid>,
        to_world: Affine3A,
        use_grid_bbox: bool,
        filter: Filter,
        wrap: Wrap,
    ) -> Option<Self> {
        let mut placed = to_world;
        if use_grid_bbox {
            let (lo, hi) = (Vec3::from_array(data.bbox.0), Vec3::from_array(data.bbox.1));
            let extent = hi - lo;
            if !(extent.min_element() > 0.0) {
                return None;
            }
            // to_local = scale(1 / extent) * translate(-lo) * to_local.
            placed = to_world * Affine3A::from_translation(lo) * Affine3A::from_scale(extent);
        }
        if !(placed.matrix3.determinant().abs() > 0.0) {
            return None;
        }
        let to_local = placed.inverse();
        to_local.is_finite().then(|| Grid {
            bbox: Aabb::of_unit_cube(&placed),
            data,
            to_world,
            use_grid_bbox,
            filter,
            wrap,
            to_local,
        })
    }

    /// The value at world point `p`.
    #[inline]
    pub fn eval(&self, p: Vec3) -> Color {
        self.eval_local(self.to_local.transform_point3(p))
    }

    /// The value at point `q` of the unit cube's coordinates.
    #[inline]
    fn eval_local(&self, q: Vec3) -> Color {
        if self.data.channels == 1 {
            Color::splat(self.lookup::<f32>(q))
        } else {
            self.lookup::<Color>(q)
        }
    }

    #[inline]
    fn lookup<T: Texel>(&self, q: Vec3) -> T {
        let res = Vec3::from_array(self.data.res.map(|r| r as f32));
        match self.filter {
            Filter::Nearest => {
                let c = (q * res).floor();
                self.cell(c.x as i32, c.y as i32, c.z as i32)
            }
            Filter::Trilinear => {
                // Between cell centres, at (i + 0.5) / res (drjit's texture lookup).
                let f = q * res - Vec3::splat(0.5);
                let c = f.floor();
                trilerp(&self.corners(c), f - c)
            }
        }
    }

    /// Cell (`x`, `y`, `z`)'s value, read by the wrap mode.
    #[inline]
    fn cell<T: Texel>(&self, x: i32, y: i32, z: i32) -> T {
        let [nx, ny, nz] = self.data.res.map(|r| r as i32);
        let (x, y, z) = (wrap(x, nx, self.wrap), wrap(y, ny, self.wrap), wrap(z, nz, self.wrap));
        let i = (z as usize * ny as usize + y as usize) * nx as usize + x as usize;
        T::read(&self.data.data, i * self.data.channels as usize)
    }

    /// World to the grid's unit cube.
    #[inline]
    pub(super) fn to_local(&self) -> &Affine3A {
        &self.to_local
    }

    /// The largest value, over channels, of the cells `lo` to `hi`
    /// (inclusive, per axis) read by the wrap mode: indices outside the
    /// grid name the cells a lookup there reads.
    pub(super) fn block_max(&self, lo: [i32; 3], hi: [i32; 3]) -> f32 {
        let mut m = 0.0f32;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let v = match self.data.channels {
                        1 => self.cell::<f32>(x, y, z),
                        _ => self.cell::<Color>(x, y, z).max_element(),
                    };
                    m = m.max(v);
                }
            }
        }
        m
    }

    /// The eight cells from `c` to `c` + (1, 1, 1), x fastest.
    #[inline]
    fn corners<T: Texel>(&self, c: Vec3) -> [T; 8] {
        let [nx, ny, nz] = self.data.res.map(|r| r as i32);
        let (x, y, z) = (c.x as i32, c.y as i32, c.z as i32);
        let axis = |i: i32, n: i32| [wrap(i, n, self.wrap) as usize, wrap(i.saturating_add(1), n, self.wrap) as usize];
        let (xs, ys, zs) = (axis(x, nx), axis(y, ny), axis(z, nz));
        let (nx, ny, channels) = (nx as usize, ny as usize, self.data.channels as usize);
        std::array::from_fn(|i| {
            let at = (zs[i >> 2] * ny + ys[(i >> 1) & 1]) * nx + xs[i & 1];
            T::read(&self.data.data, at * channels)
        })
    }
}

/// A grid's value as the arithmetic reads it: a one-channel grid's as one
/// number, three times cheaper than a colour of three equal channels and
/// the same to the bit (glam's `Vec3` computes channel by channel).
trait Texel: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<f32, Output = Self> + AddAssign {
    const ZERO: Self;
    fn read(data: &[f32], at: usize) -> Self;
    fn max_element(self) -> f32;
    fn color(self) -> Color;
}

impl Texel for f32 {
    const ZERO: f32 = 0.0;
    #[inline]
    fn read(data: &[f32], at: usize) -> f32 {
        data[at]
    }
    #[inline]
    fn max_element(self) -> f32 {
        self
    }
    #[inline]
    fn color(self) -> Color {
        Color::splat(self)
    }
}

impl Texel for Color {
    const ZERO: Color = Color::ZERO;
    #[inline]
    fn read(data: &[f32], at: usize) -> Color {
        Color::new(data[at], data[at + 1], data[at + 2])
    }
    #[inline]
    fn max_element(self) -> f32 {
        Vec3::max_element(self)
    }
    #[inline]
    fn color(self) -> Color {
        self
    }
}

/// Trilinear interpolation of `v` (x fastest) at weights `w`.
#[inline]
fn trilerp<T: Texel>(v: &[T; 8], w: Vec3) -> T {
    let lerp = |a: T, b: T, t: f32| a + (b - a) * t;
    let x00 = lerp(v[0], v[1], w.x);
    let x10 = lerp(v[2], v[3], w.x);
    let x01 = lerp(v[4], v[5], w.x);
    let x11 = lerp(v[6], v[7], w.x);
    lerp(lerp(x00, x10, w.y), lerp(x01, x11, w.y), w.z)
}

impl Grid {
    /// The integral of the grid's value along `ray` over [`t0`, `t1`],
    /// exact to rounding: `piece` is told the distance at the end of each
    /// piece and the integral up to it. The walk visits every piece
    /// between the planes where the lookup changes formula (cell centres
    /// for trilinear lookups, cell faces for the nearest), as Amanatides
    /// and Woo's voxel traversal does (1987); within a piece a trilinear
    /// lookup along a line is a cubic in t (a constant for the nearest
    /// cell), which two-point Gauss–Legendre integrates exactly. A piece
    /// whose integral exceeds `fine` in some channel is cut into equal
    /// parts below it, so that a reader interpolating between the
    /// pieces' ends errs little.
    pub fn integrate(&self, ray: &Ray, t0: f32, t1: f32, fine: f32, piece: impl FnMut(f32, Color)) -> Color {
        if self.data.channels == 1 {
            self.integrate_as::<f32>(ray, t0, t1, fine, piece).color()
        } else {
            self.integrate_as::<Color>(ray, t0, t1, fine, piece)
        }
    }

    #[inline]
    fn integrate_as<T: Texel>(&self, ray: &Ray, t0: f32, t1: f32, fine: f32, mut piece: impl FnMut(f32, Color)) -> T {
        let res = Vec3::from_array(self.data.res.map(|r| r as f32));
        let shift = match self.filter {
            Filter::Trilinear => 0.5,
            Filter::Nearest => 0.0,
        };
        // Grid coordinates along the ray: g(t) = g0 + dg t, the lookup's
        // formula changing where a coordinate crosses an integer.
        let g0 = self.to_local.transform_point3(ray.origin) * res - Vec3::splat(shift);
        let dg = self.to_local.transform_vector3(ray.dir) * res;

        let mut next = Vec3::splat(f32::INFINITY);
        let mut step = Vec3::splat(f32::INFINITY);
        for a in 0..3 {
            if dg[a] != 0.0 {
                let g = g0[a] + dg[a] * t0;
                let boundary = if dg[a] > 0.0 { g.floor() + 1.0 } else { g.ceil() - 1.0 };
                next[a] = (boundary - g0[a]) / dg[a];
                step[a] = 1.0 / dg[a].abs();
            }
        }
        // Within a piece the lookup reads one set of cells: fetched once,
        // the cubic integrated by two-point Gauss–Legendre (nodes at
        // ±1/√3 of the half-width), the nearest cell's constant exactly.
        let node = 1.0 / 3f32.sqrt();
        let filter = self.filter;
        let integral = |a: f32, b: f32, cells: &[T; 8], c: Vec3| -> T {
            match filter {
                Filter::Nearest => cells[0] * (b - a),
                Filter::Trilinear => {
                    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
                    let w = |t: f32| (g0 + dg * t - c).clamp(Vec3::ZERO, Vec3::ONE);
                    (trilerp(cells, w(mid - node * half)) + trilerp(cells, w(mid + node * half))) * half
                }
            }
        };
        let cells_of = |t: f32| {
            let c = (g0 + dg * t).floor();
            let cells = match filter {
                Filter::Nearest => [self.cell(c.x as i32, c.y as i32, c.z as i32); 8],
                Filter::Trilinear => self.corners(c),
            };
            (cells, c)
        };
        // At most one piece per plane crossed, and the last.
        let bound = ((dg.abs() * (t1 - t0)).element_sum() + 4.0).min(1e7) as usize;
        let mut sum = T::ZERO;
        let mut t = t0;
        for _ in 0..bound {
            let end = next.min_element().min(t1).max(t);
            let (cells, c) = cells_of(0.5 * (t + end));
            let whole = integral(t, end, &cells, c);
            let parts = (whole.max_element() / fine).ceil();
            if parts > 1.0 && parts.is_finite() {
                let (n, h) = (parts as usize, (end - t) / parts);
                for i in 0..n {
                    let (a, b) = (t + i as f32 * h, if i + 1 == n { end } else { t + (i + 1) as f32 * h });
                    sum += integral(a, b, &cells, c);
                    piece(b, sum.color());
                }
            } else {
                sum += whole;
                piece(end, sum.color());
            }
            if !(end < t1) {
                break;
            }
            t = end;
            for a in 0..3 {
                if next[a] <= end {
                    next[a] += step[a];
                }
            }
        }
        sum
    }
}

/// Cell index `i` of `n` read by wrap mode `mode`. Coordinates far outside
/// the grid arrive as saturated integers and stay in range.
#[inline]
fn wrap(i: i32, n: i32, mode: Wrap) -> i32 {
    match mode {
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Mirror => {
            // ... 1 0 | 0 1 ... n-1 | n-1 n-2 ...
            let period = i.rem_euclid(2 * n);
            if period < n {
                period
            } else {
                2 * n - 1 - period
            }
        }
    }
}

impl Volume {
    #[inline]
    pub fn eval(&self, p: Vec3) -> Color {
        match self {
            Volume::Constant { value, .. } => *value,
            Volume::Grid(g) => g.eval(p),
        }
    }

    /// The integral of the value along `ray` over [`t0`, `t1`], exact to
    /// rounding, told piece by piece as [`Grid::integrate`] tells it.
    pub fn integrate(&self, ray: &Ray, t0: f32, t1: f32, fine: f32, mut piece: impl FnMut(f32, Color)) -> Color {
        match self {
            Volume::Constant { value, .. } => {
                let parts = (value.max_element() * (t1 - t0) / fine).ceil().clamp(1.0, 1e6) as usize;
                let h = (t1 - t0) / parts as f32;
                for i in 1..=parts {
                    piece(if i == parts { t1 } else { t0 + i as f32 * h }, *value * (i as f32 * h));
                }
                *value * (t1 - t0)
            }
            Volume::Grid(g) => g.integrate(ray, t0, t1, fine, piece),
        }
    }

    /// The largest value over the volume and its channels (Mitsuba's
    /// `Volume::max`, a heterogeneous medium's majorant before its scale).
    pub fn max(&self) -> f32 {
        match self {
            Volume::Constant { value, .. } => value.max_element(),
            Volume::Grid(g) => g.data.max(),
        }
    }

    /// The smallest value over the volume and its channels.
    pub fn min(&self) -> f32 {
        match self {
            Volume::Constant { value, .. } => value.min_element(),
            Volume::Grid(g) => g.data.data.iter().copied().fold(f32::INFINITY, f32::min),
        }
    }

    /// The world bounds of the volume's unit cube.
    pub fn bbox(&self) -> Aabb {
        match self {
            Volume::Constant { to_world, .. } => Aabb::of_unit_cube(to_world),
            Volume::Grid(g) => g.bbox,
        }
    }

    /// Whether the value is the same everywhere.
    pub fn constant(&self) -> Option<Color> {
        match self {
            Volume::Constant { value, .. } => Some(*value),
            Volume::Grid(_) => None,
        }
    }

    /// The same volume in a scene whose lengths are multiplied by `s`.
    pub fn scaled(&self, s: f32) -> Volume {
        let scale = Affine3A::from_scale(Vec3::splat(s));
        match self {
            Volume::Constant { value, to_world } => Volume::Constant { value: *value, to_world: scale * *to_world },
            Volume::Grid(g) => Volume::Grid(
                Grid::new(g.data.clone(), scale * g.to_world, g.use_grid_bbox, g.filter, g.wrap)
                    .unwrap_or_else(|| g.clone()),
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(filter: Filter, wrap: Wrap) -> Grid {
        // 4 x 2 x 2, one channel, value = x index.
        let data = (0..16).map(|i| (i % 4) as f32).collect();
        let vol = VolGrid { res: [4, 2, 2], channels: 1, bbox: ([0.0; 3], [1.0; 3]), data };
        Grid::new(Arc::new(vol), Affine3A::IDENTITY, false, filter, wrap).unwrap()
    }

    /// A one-channel grid, read and integrated as one number, gives to the
    /// bit what the same grid stored as three equal channels gives: for
    /// every filter and wrap mode, lookups inside and outside the cube and
    /// integrals along random segments, piece by piece.
    #[test]
    fn a_grey_grid_reads_as_its_three_channel_copy() {
        use crate::sampling::{stream, Domain};
        use rand::RngExt;
        let mut rng = stream(5, Domain::Camera, 1);
        let values: Vec<f32> = (0..5 * 4 * 3).map(|_| rng.random::<f32>() * 3.0).collect();
        let grey = VolGrid { res: [5, 4, 3], channels: 1, bbox: ([0.0; 3], [1.0; 3]), data: values.clone() };
        let rgb = VolGrid { channels: 3, data: values.iter().flat_map(|&v| [v; 3]).collect(), ..grey.clone() };
        let place = Affine3A::from_scale_rotation_translation(
            Vec3::new(1.5, 0.7, 2.0),
            glam::Quat::from_rotation_y(0.4),
            Vec3::new(-0.3, 0.2, 0.1),
        );
        for filter in [Filter::Trilinear, Filter::Nearest] {
            for wrap in [Wrap::Clamp, Wrap::Repeat, Wrap::Mirror] {
                let a = Grid::new(Arc::new(grey.clone()), place, false, filter, wrap).unwrap();
                let b = Grid::new(Arc::new(rgb.clone()), place, false, filter, wrap).unwrap();
                for _ in 0..300 {
                    let p = Vec3::new(rng.random(), rng.random(), rng.random()) * 5.0 - Vec3::splat(1.5);
                    assert_eq!(a.eval(p), b.eval(p), "{p} {filter:?} {wrap:?}");
                    let dir = (Vec3::new(rng.random(), rng.random(), rng.random()) - Vec3::splat(0.5)).normalize();
                    let ray = Ray::new(p, dir);
                    let (mut pa, mut pb) = (Vec::new(), Vec::new());
                    let ia = a.integrate(&ray, 0.1, 4.0, 0.05, |t, tau| pa.push((t, tau)));
                    let ib = b.integrate(&ray, 0.1, 4.0, 0.05, |t, tau| pb.push((t, tau)));
                    assert_eq!(ia, ib);
                    assert_eq!(pa, pb);
                    assert_eq!(ia.x, ia.y);
                }
            }
        }
    }

    /// Trilinear lookups run linearly between cell centres and clamp at
    /// the edges; the nearest cell is the one holding the point.
    #[test]
    fn lookups_interpolate_between_cell_centres() {
        let g = ramp(Filter::Trilinear, Wrap::Clamp);
        let at = |x: f32| g.eval(Vec3::new(x, 0.3, 0.8)).x;
        assert!((at(0.125) - 0.0).abs() < 1e-6);
        assert!((at(0.25) - 0.5).abs() < 1e-6);
        assert!((at(0.5) - 1.5).abs() < 1e-6);
        assert!((at(0.875) - 3.0).abs() < 1e-6);
        assert_eq!(at(0.99), 3.0);
        assert_eq!(at(-5.0), 0.0);
        let n = ramp(Filter::Nearest, Wrap::Clamp);
        assert_eq!(n.eval(Vec3::new(0.49, 0.5, 0.5)).x, 1.0);
        assert_eq!(n.eval(Vec3::new(0.51, 0.5, 0.5)).x, 2.0);
        let r = ramp(Filter::Nearest, Wrap::Repeat);
        assert_eq!(r.eval(Vec3::new(1.1, 0.5, 0.5)).x, 0.0);
        assert_eq!(r.eval(Vec3::new(-0.1, 0.5, 0.5)).x, 3.0);
        let m = ramp(Filter::Nearest, Wrap::Mirror);
        assert_eq!(m.eval(Vec3::new(1.1, 0.5, 0.5)).x, 3.0);
        assert_eq!(m.eval(Vec3::new(-0.1, 0.5, 0.5)).x, 0.0);
        assert_eq!(m.eval(Vec3::new(-0.3, 0.5, 0.5)).x, 1.0);
        // Trilinear with repeat blends the last cell into the first.
        let t = ramp(Filter::Trilinear, Wrap::Repeat);
        assert!((t.eval(Vec3::new(1.0, 0.5, 0.5)).x - 1.5).abs() < 1e-6);
    }

    /// to_world places the unit cube; use_grid_bbox first maps the file's
    /// box onto it.
    #[test]
    fn transforms_place_the_grid() {
        let data = (0..16).map(|i| (i % 4) as f32).collect();
        let vol = Arc::new(VolGrid { res: [4, 2, 2], channels: 1, bbox: ([2.0, 0.0, 0.0], [6.0, 1.0, 1.0]), data });
        let to_world = Affine3A::from_translation(Vec3::new(-0.5, 0.0, 0.0)) * Affine3A::from_scale(Vec3::splat(2.0));
        let g = Grid::new(vol.clone(), to_world, false, Filter::Nearest, Wrap::Clamp).unwrap();
        assert_eq!(g.bbox, Aabb { lo: Vec3::new(-0.5, 0.0, 0.0), hi: Vec3::new(1.5, 2.0, 2.0) });
        assert_eq!(g.eval(Vec3::new(1.4, 1.0, 1.0)).x, 3.0);
        let b = Grid::new(vol, Affine3A::IDENTITY, true, Filter::Nearest, Wrap::Clamp).unwrap();
        assert_eq!(b.bbox, Aabb { lo: Vec3::new(2.0, 0.0, 0.0), hi: Vec3::new(6.0, 1.0, 1.0) });
        assert_eq!(b.eval(Vec3::new(4.5, 0.5, 0.5)).x, 2.0);
    }

    #[test]
    fn a_box_clips_rays_to_its_inside() {
        let b = Aabb { lo: Vec3::splat(-1.0), hi: Vec3::splat(1.0) };
        let r = Ray::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::X);
        assert_eq!(b.clip(&r, 10.0), Some((2.0, 4.0)));
        assert_eq!(b.clip(&r, 3.0), Some((2.0, 3.0)));
        assert_eq!(b.clip(&r, 1.0), None);
        let inside = Ray::new(Vec3::ZERO, Vec3::Y);
        assert_eq!(b.clip(&inside, 10.0), Some((0.0, 1.0)));
        let miss = Ray::new(Vec3::new(-3.0, 2.0, 0.0), Vec3::X);
        assert_eq!(b.clip(&miss, 10.0), None);
    }
}
