//! A signed distance function sampled on a grid, as Mitsuba 3's `sdfgrid`
//! shape defines it (src/shapes/sdfgrid.cpp; Hansson-Söderlund, Evans and
//! Akenine-Möller, "Ray tracing of signed distance function grids", JCGT
//! 11(3), 2022):
//!
//! - the grid's samples sit at the corners of its voxels, spanning the
//!   object's [0, 1]^3 (sample i of n at i / (n - 1)); between them the
//!   function is trilinear, and beyond them it is held at the border's
//!   value (Mitsuba's texture with clamping);
//! - the surface is where the trilinear function is zero; a ray meets it
//!   at the first sign change along the ray, found per voxel as a root of
//!   the cubic the function is along a line;
//! - the geometric normal is the gradient of the voxel's trilinear
//!   function at the hit (outwards: towards positive values), carried to
//!   world space as a normal; `smooth` shading normals blend the normalised
//!   gradients of the eight voxels around the nearest sample by their
//!   distances (the paper's §5), as Mitsuba's `smooth_sh` does.
//!
//! Mitsuba makes each voxel the surface crosses a primitive of its BVH;
//! here the grid is one primitive that walks its voxels along the ray
//! (Amanatides and Woo, 1987), skipping those the surface does not cross.
//! A ray leaving the surface knows which way it left, so it never meets
//! the surface again at its own origin: leaving towards positive values
//! the next hit must enter (the function falls through zero), leaving
//! towards negative values it must exit. Mitsuba's texture coordinates on
//! the grid are zero, as here.
//!
//! The grid is read as Mitsuba reads it for a cubic grid; for a grid of
//! unequal resolutions Mitsuba's code takes each axis's voxel size from the
//! opposite axis's resolution (its sizes are indexed in the tensor's z, y,
//! x order), which this does not reproduce.

use super::{ShapeHit, FLAT};
use crate::math::{gamma, Ray, Vertex};
use glam::{DAffine3, DMat3, DVec3, Vec3};

/// How the shading normal is found (Mitsuba's `normals`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normals {
    /// The geometric normal.
    Analytic,
    /// The blend of the neighbouring voxels' gradients.
    Smooth,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SdfGrid {
    /// Samples along x, y and z (each at least 2).
    res: [usize; 3],
    /// x fastest, then y, then z.
    values: Vec<f32>,
    /// Per voxel (x fastest), whether the surface may cross it: its
    /// corners are not all of one strict sign.
    crossed: Vec<bool>,
    /// The crossed voxels' range, [lo, hi) per axis.
    lo: [usize; 3],
    hi: [usize; 3],
    to_world: DAffine3,
    /// World to voxel coordinates (voxel (i, j, k) spans [i, i + 1] x ...).
    to_voxel: DAffine3,
    /// Object-space normals to world space (the inverse transpose).
    normal_map: DMat3,
    normals: Normals,
    /// The world box around the crossed voxels.
    bounds: (Vec3, Vec3),
}

/// Voxels read in a row before the walk gives up on a ray (a grid's
/// diagonal is at most three times its largest side).
const MAX_STEPS: usize = 1 << 20;

impl SdfGrid {
    /// The grid of `res` samples (x fastest) placed by `to_world`, or why
    /// it cannot be one.
    pub fn new(res: [usize; 3], values: Vec<f32>, to_world: DAffine3, normals: Normals) -> Result<Self, String> {
        if res.iter().any(|&n| n < 2) {
            return Err(format!(
                "a grid of {} x {} x {} samples has no voxel (2 per axis at least)",
                res[0], res[1], res[2]
            ));
        }
        if values.len() != res[0] * res[1] * res[2] {
            return Err(format!("{} values for {} x {} x {} samples", values.len(), res[0], res[1], res[2]));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(format!("sample {i} is not finite ({})", values[i]));
        }
        if !(to_world.matrix3.determinant().abs() > 0.0) || !to_world.is_finite() {
            return Err("the transform is singular".into());
        }
        let to_object = to_world.inverse();
        let scale = DVec3::new((res[0] - 1) as f64, (res[1] - 1) as f64, (res[2] - 1) as f64);
        let to_voxel = DAffine3::from_scale(scale) * to_object;
        let [nx, ny, nz] = res.map(|n| n - 1);
        let mut crossed = vec![false; nx * ny * nz];
        let (mut lo, mut hi) = ([usize::MAX; 3], [0; 3]);
        let value = |x: usize, y: usize, z: usize| values[(z * res[1] + y) * res[0] + x];
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let corners = (0..8).map(|c| value(x + (c & 1), y + (c >> 1 & 1), z + (c >> 2 & 1)));
                    let (pos, neg) = corners.fold((true, true), |(p, n), v| (p && v > 0.0, n && v < 0.0));
                    if !(pos || neg) {
                        crossed[(z * ny + y) * nx + x] = true;
                        for (a, i) in [x, y, z].into_iter().enumerate() {
                            lo[a] = lo[a].min(i);
                            hi[a] = hi[a].max(i + 1);
                        }
                    }
                }
            }
        }
        if lo[0] == usize::MAX {
            return Err("the surface crosses no voxel of the grid (its samples are all of one sign)".into());
        }
        let mut grid = SdfGrid {
            res,
            values,
            crossed,
            lo,
            hi,
            to_world,
            to_voxel,
            normal_map: to_object.matrix3.transpose(),
            normals,
            bounds: (Vec3::ZERO, Vec3::ZERO),
        };
        let (mut a, mut b) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for p in grid.corners() {
            a = a.min(p);
            b = b.max(p);
        }
        grid.bounds = (a, b);
        Ok(grid)
    }

    /// The same grid with every length times `s` about the origin.
    pub fn scaled(&self, s: f32) -> Self {
        let m = DAffine3::from_scale(DVec3::splat(s as f64)) * self.to_world;
        SdfGrid::new(self.res, self.values.clone(), m, self.normals).unwrap_or_else(|_| self.clone())
    }

    pub fn to_world(&self) -> DAffine3 {
        self.to_world
    }

    /// The world corners of the crossed voxels' box.
    fn corners(&self) -> impl Iterator<Item = Vec3> + '_ {
        let to_world = self.to_world * self.to_voxel_object();
        (0..8).map(move |c| {
            let pick = |a: usize| if c >> a & 1 == 1 { self.hi[a] } else { self.lo[a] } as f64;
            to_world.transform_point3(DVec3::new(pick(0), pick(1), pick(2))).as_vec3()
        })
    }

    /// Voxel coordinates to the object's [0, 1]^3.
    fn to_voxel_object(&self) -> DAffine3 {
        let [x, y, z] = self.res.map(|n| 1.0 / (n - 1) as f64);
        DAffine3::from_scale(DVec3::new(x, y, z))
    }

    #[inline]
    fn sample(&self, x: usize, y: usize, z: usize) -> f64 {
        self.values[(z * self.res[1] + y) * self.res[0] + x] as f64
    }

    /// The function at object point `p`: trilinear, held at the border.
    fn field(&self, p: DVec3) -> f64 {
        let mut i = [0usize; 3];
        let mut w = [0f64; 3];
        for a in 0..3 {
            let n = self.res[a];
            let c = (p[a] * (n - 1) as f64).clamp(0.0, (n - 1) as f64);
            let i0 = (c.floor() as usize).min(n - 2);
            i[a] = i0;
            w[a] = c - i0 as f64;
        }
        let mut f = 0.0;
        for c in 0..8 {
            let (dx, dy, dz) = (c & 1, c >> 1 & 1, c >> 2 & 1);
            let weight = (if dx == 1 { w[0] } else { 1.0 - w[0] })
                * (if dy == 1 { w[1] } else { 1.0 - w[1] })
                * (if dz == 1 { w[2] } else { 1.0 - w[2] });
            f += weight * self.sample(i[0] + dx, i[1] + dy, i[2] + dz);
        }
        f
    }

    /// Mitsuba's `voxel_grad`: the differences of the function across
    /// voxel `v` along each axis, at `p`'s other two coordinates (the
    /// gradient of `v`'s trilinear function where `p` lies in `v`).
    fn voxel_grad(&self, p: DVec3, v: [i64; 3]) -> DVec3 {
        let mut g = DVec3::ZERO;
        for a in 0..3 {
            let size = 1.0 / (self.res[a] - 1) as f64;
            let (mut lo, mut hi) = (p, p);
            lo[a] = v[a] as f64 * size;
            hi[a] = lo[a] + size;
            g[a] = (self.field(hi) - self.field(lo)) / size;
        }
        g
    }

    /// Mitsuba's `smooth_sh`: the normalised gradients of the eight voxels
    /// around the sample nearest `p`, blended by `p`'s place between their
    /// centres; voxels below the grid's first sample count for nothing.
    fn smooth(&self, p: DVec3) -> DVec3 {
        let scaled =
            DVec3::new(p.x * (self.res[0] - 1) as f64, p.y * (self.res[1] - 1) as f64, p.z * (self.res[2] - 1) as f64);
        let v111 = scaled.round();
        let base = [v111.x as i64 - 1, v111.y as i64 - 1, v111.z as i64 - 1];
        let mut n = [DVec3::ZERO; 8];
        let mut valid = [false; 8];
        for c in 0..8 {
            let v = [base[0] + (c & 1) as i64, base[1] + (c >> 1 & 1) as i64, base[2] + (c >> 2 & 1) as i64];
            valid[c] = v.iter().all(|&i| i >= 0);
            if valid[c] {
                n[c] = self.voxel_grad(p, v).normalize_or_zero();
            }
        }
        let mut w = scaled - v111 + DVec3::splat(0.5);
        // An axis whose voxels on one side are all missing takes the other.
        for a in 0..3 {
            let side = |s: usize| (0..8).filter(|c| c >> a & 1 == s).all(|c| !valid[c]);
            if side(0) {
                w[a] = 1.0;
            }
            if side(1) {
                w[a] = 0.0;
            }
        }
        let mut sum = DVec3::ZERO;
        for (c, nc) in n.iter().enumerate() {
            let f = |a: usize| if c >> a & 1 == 1 { w[a] } else { 1.0 - w[a] };
            sum += *nc * (f(0) * f(1) * f(2));
        }
        sum
    }

    /// The function along the ray inside voxel `v`, as the cubic
    /// c0 + c1 t + c2 t² + c3 t³ in the ray's parameter, from the voxel
    /// coordinates `o + t d` of its points.
    fn cubic(&self, v: [usize; 3], o: DVec3, d: DVec3) -> [f64; 4] {
        // Linear weights along each axis: (1 - x, x) with x = a + b t.
        let axis = |a: usize| {
            let (x0, x1) = (o[a] - v[a] as f64, d[a]);
            [[1.0 - x0, -x1], [x0, x1]]
        };
        let (wx, wy, wz) = (axis(0), axis(1), axis(2));
        let mul1 = |p: [f64; 2], q: [f64; 2]| [p[0] * q[0], p[0] * q[1] + p[1] * q[0], p[1] * q[1]];
        let mut out = [0.0; 4];
        for (dz, w) in wz.iter().enumerate() {
            let mut along_y = [0.0; 3];
            for (dy, wy) in wy.iter().enumerate() {
                let s0 = self.sample(v[0], v[1] + dy, v[2] + dz);
                let s1 = self.sample(v[0] + 1, v[1] + dy, v[2] + dz);
                let line = [s0 * wx[0][0] + s1 * wx[1][0], s0 * wx[0][1] + s1 * wx[1][1]];
                for (sum, q) in along_y.iter_mut().zip(mul1(line, *wy)) {
                    *sum += q;
                }
            }
            out[0] += along_y[0] * w[0];
            out[1] += along_y[0] * w[1] + along_y[1] * w[0];
            out[2] += along_y[1] * w[1] + along_y[2] * w[0];
            out[3] += along_y[2] * w[1];
        }
        out
    }

    /// Distance to the first hit in (0, t_max); `departed`: `Some(towards
    /// positive values)` for a ray leaving this grid's surface. Never
    /// inlined: `Shape::distance`, in every ray's inner loop, stays as
    /// small as it was without grids.
    #[inline(never)]
    pub fn distance(&self, ray: &Ray, t_max: f32, departed: Option<bool>) -> Option<f32> {
        let o = self.to_voxel.transform_point3(ray.origin.as_dvec3());
        let d = self.to_voxel.transform_vector3(ray.dir.as_dvec3());
        // The crossed voxels' box: the slabs.
        let (mut t0, mut t1) = (0.0f64, t_max as f64);
        for a in 0..3 {
            let inv = 1.0 / d[a];
            let (mut near, mut far) = ((self.lo[a] as f64 - o[a]) * inv, (self.hi[a] as f64 - o[a]) * inv);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            if near.is_nan() || far.is_nan() {
                // Parallel to the slab: inside it or never.
                if o[a] < self.lo[a] as f64 || o[a] > self.hi[a] as f64 {
                    return None;
                }
                continue;
            }
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        if !(t0 <= t1) {
            return None;
        }
        // The walk from the voxel holding the entry point.
        let entry = o + d * t0;
        let mut v = [0usize; 3];
        let mut step = [0i64; 3];
        let mut next = [f64::INFINITY; 3];
        let mut delta = [f64::INFINITY; 3];
        for a in 0..3 {
            v[a] = (entry[a].floor().max(self.lo[a] as f64) as usize).min(self.hi[a] - 1);
            if d[a] > 0.0 {
                step[a] = 1;
                next[a] = (v[a] as f64 + 1.0 - o[a]) / d[a];
                delta[a] = 1.0 / d[a];
            } else if d[a] < 0.0 {
                step[a] = -1;
                next[a] = (v[a] as f64 - o[a]) / d[a];
                delta[a] = -1.0 / d[a];
            }
        }
        let [nx, ny, _] = self.res.map(|n| n - 1);
        let mut start = t0;
        for _ in 0..MAX_STEPS {
            let a = if next[0] <= next[1] && next[0] <= next[2] {
                0
            } else if next[1] <= next[2] {
                1
            } else {
                2
            };
            let end = next[a].min(t1);
            if self.crossed[(v[2] * ny + v[1]) * nx + v[0]] {
                if let Some(t) = first_root(self.cubic(v, o, d), start, end, departed) {
                    return Some(t as f32).filter(|&t| t > 0.0 && t < t_max);
                }
            }
            if next[a] >= t1 {
                return None;
            }
            start = next[a];
            let i = v[a] as i64 + step[a];
            if i < self.lo[a] as i64 || i >= self.hi[a] as i64 {
                return None;
            }
            v[a] = i as usize;
            next[a] += delta[a];
        }
        None
    }

    #[inline(never)]
    pub fn record(&self, ray: &Ray, t: f32) -> ShapeHit {
        let point = ray.at(t);
        let world = ray.origin.as_dvec3() + ray.dir.as_dvec3() * t as f64;
        let voxel = self.to_voxel.transform_point3(world);
        let p = self.to_voxel_object().transform_point3(voxel);
        let v = [0, 1, 2].map(|a| (voxel[a].floor() as i64).clamp(0, self.res[a] as i64 - 2));
        let world_normal = |n: DVec3| (self.normal_map * n).try_normalize();
        let normal = world_normal(self.voxel_grad(p, v)).unwrap_or(-ray.dir.as_dvec3()).as_vec3();
        let shading_normal = match self.normals {
            Normals::Analytic => None,
            Normals::Smooth => world_normal(self.smooth(p))
                .map(|n| n.as_vec3())
                .filter(|n| n.dot(normal) > 0.0 && (*n - normal).length_squared() > 0.0),
        };
        let p_err = gamma(8) * (ray.origin.abs() + (ray.dir * t).abs() + point.abs());
        ShapeHit { t, point, p_err, normal, uv: [0.0; 2], shading: FLAT, shading_normal }
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    pub fn bounding_sphere(&self) -> (Vertex, f32) {
        let c = (self.bounds.0 + self.bounds.1) * 0.5;
        (c, self.corners().map(|p| p.distance(c)).fold(0.0, f32::max))
    }

    pub fn extent_along(&self, u: Vec3) -> (f32, f32) {
        self.corners().map(|p| p.dot(u)).fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)))
    }
}

/// The first t in [t0, t1] where the cubic `c` changes sign, in the
/// direction `departed` allows (leaving towards positive values, only a
/// fall through zero; towards negative values, only a rise). The cubic is
/// monotone between the roots of its derivative: each such piece holds at
/// most one crossing, found by bisection to the precision of f64.
fn first_root(c: [f64; 4], t0: f64, t1: f64, departed: Option<bool>) -> Option<f64> {
    if !(t0 <= t1) {
        return None;
    }
    let f = |t: f64| ((c[3] * t + c[2]) * t + c[1]) * t + c[0];
    // The derivative c1 + 2 c2 t + 3 c3 t².
    let mut cuts = [t1; 3];
    let (a, b, q) = (3.0 * c[3], 2.0 * c[2], c[1]);
    let mut n = 0;
    if a != 0.0 {
        let disc = b * b - 4.0 * a * q;
        if disc > 0.0 {
            let s = disc.sqrt();
            let k = -0.5 * (b + s.copysign(b));
            let (mut r0, mut r1) = (k / a, if k != 0.0 { q / k } else { k / a });
            if r0 > r1 {
                std::mem::swap(&mut r0, &mut r1);
            }
            for r in [r0, r1] {
                if r > t0 && r < t1 {
                    cuts[n] = r;
                    n += 1;
                }
            }
        }
    } else if b != 0.0 {
        let r = -q / b;
        if r > t0 && r < t1 {
            cuts[n] = r;
            n += 1;
        }
    }
    let mut lo = t0;
    let mut f_lo = f(lo);
    for &hi in cuts.iter().take(n + 1) {
        let f_hi = f(hi);
        let rises = f_lo <= 0.0 && f_hi > 0.0;
        let falls = f_lo > 0.0 && f_hi <= 0.0;
        let allowed = match departed {
            None => rises || falls,
            Some(true) => falls,
            Some(false) => rises,
        };
        if allowed {
            let (mut a, mut b) = (lo, hi);
            for _ in 0..200 {
                let m = 0.5 * (a + b);
                if !(m > a && m < b) {
                    break;
                }
                if (f(m) > 0.0) == (f_lo > 0.0) {
                    a = m;
                } else {
                    b = m;
                }
            }
            // The end on the far side of zero: the crossing is not before it.
            return Some(b);
        }
        lo = hi;
        f_lo = f_hi;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere of radius 0.3 about the grid's centre, sampled as its
    /// signed distance on n³ points.
    fn ball(n: usize, to_world: DAffine3) -> SdfGrid {
        let mut values = Vec::new();
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let p = DVec3::new(x as f64, y as f64, z as f64) / (n - 1) as f64;
                    values.push(((p - DVec3::splat(0.5)).length() - 0.3) as f32);
                }
            }
        }
        SdfGrid::new([n; 3], values, to_world, Normals::Smooth).unwrap()
    }

    /// The trilinear surface of a sampled sphere lies within the sampling's
    /// error of the sphere, its normals point out of it, and the cubic
    /// along a ray agrees with the function read point by point.
    #[test]
    fn a_sampled_sphere_is_met_where_the_sphere_is() {
        let m = DAffine3::from_translation(DVec3::new(1.0, -2.0, 0.5)) * DAffine3::from_scale(DVec3::splat(4.0));
        let g = ball(33, m);
        let centre = m.transform_point3(DVec3::splat(0.5)).as_vec3();
        let mut state = 7u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 40) as f32) / (1u64 << 24) as f32
        };
        let mut hits = 0;
        for _ in 0..2000 {
            let dir = crate::sampling::uniform_cone(glam::Vec2::new(next(), next()), -1.0).normalize();
            let aim = centre + 1.5 * Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            let ray = Ray::new(aim - dir * 10.0, dir);
            let sphere = crate::shape::Sphere { center: centre, radius: 1.2 };
            let exact = sphere.distance(&ray, f32::INFINITY, None);
            let found = g.distance(&ray, f32::INFINITY, None);
            match (exact, found) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    // A grid of 32 voxels over 4 units: the trilinear surface
                    // stays within a few thousandths of the sphere.
                    assert!((a - b).abs() < 0.02, "{a} vs {b}");
                    let h = g.record(&ray, b);
                    assert!(h.normal.dot((h.point - centre).normalize()) > 0.99);
                    let s = h.shading_normal.unwrap_or(h.normal);
                    assert!(s.dot((h.point - centre).normalize()) > 0.995, "{s}");
                    // Leaving outwards, the ray does not meet the ball again.
                    let out = Ray::new(h.point, (h.point - centre).normalize());
                    assert!(g.distance(&out, f32::INFINITY, Some(true)).is_none());
                    // Leaving inwards, it meets the far side.
                    let back = Ray::new(h.point, ray.dir);
                    let far = g.distance(&back, f32::INFINITY, Some(false)).expect("the far side");
                    assert!(far > 0.1, "{far}");
                }
                (None, None) => {}
                // Grazing rays may tell the two surfaces apart.
                (a, b) => assert!(
                    ray.origin.distance(centre).powi(2) - (ray.origin - centre).dot(ray.dir).powi(2) > 1.1f32.powi(2),
                    "{a:?} vs {b:?}"
                ),
            }
        }
        assert!(hits > 500, "{hits}");
        // The cubic is the function along the ray, within the voxel.
        let o = DVec3::new(3.2, 4.1, 5.7);
        let d = DVec3::new(0.3, -0.2, 0.15);
        let c = g.cubic([3, 4, 5], o, d);
        for t in [0.0, 0.2, 0.4, 0.5] {
            let p = (o + d * t) / 32.0;
            let want = g.field(p);
            let got = ((c[3] * t + c[2]) * t + c[1]) * t + c[0];
            assert!((want - got).abs() < 1e-9, "{want} vs {got}");
        }
    }

    #[test]
    fn bounds_hold_the_crossed_voxels() {
        let g = ball(17, DAffine3::from_rotation_z(0.4) * DAffine3::from_scale(DVec3::new(1.0, 2.0, 3.0)));
        let (lo, hi) = g.bounds();
        let (c, r) = g.bounding_sphere();
        for corner in g.corners() {
            assert!(corner.cmpge(lo - 1e-5).all() && corner.cmple(hi + 1e-5).all());
            assert!(corner.distance(c) <= r + 1e-5);
        }
        // The ball is 0.6 of the grid across; its box is a little more.
        assert!(g.hi[0] - g.lo[0] <= 12 && g.hi[0] - g.lo[0] >= 10, "{:?} {:?}", g.lo, g.hi);
    }

    #[test]
    fn grids_without_a_surface_are_refused() {
        let e = SdfGrid::new([2; 3], vec![1.0; 8], DAffine3::IDENTITY, Normals::Smooth).unwrap_err();
        assert!(e.contains("crosses no voxel"), "{e}");
        assert!(SdfGrid::new([1, 2, 2], vec![1.0; 4], DAffine3::IDENTITY, Normals::Smooth).is_err());
        assert!(SdfGrid::new([2; 3], vec![f32::NAN; 8], DAffine3::IDENTITY, Normals::Smooth).is_err());
    }

    #[test]
    fn the_first_crossing_of_a_cubic() {
        // (t - 1)(t - 2)(t - 3): rises through 1, falls through 2, rises through 3.
        let c = [-6.0, 11.0, -6.0, 1.0];
        let at = |r: Option<f64>| r.unwrap();
        assert!((at(first_root(c, 0.0, 4.0, None)) - 1.0).abs() < 1e-12);
        assert!((at(first_root(c, 0.0, 4.0, Some(true))) - 2.0).abs() < 1e-12);
        assert!((at(first_root(c, 1.5, 4.0, Some(false))) - 3.0).abs() < 1e-12);
        assert!(first_root(c, 3.5, 4.0, None).is_none());
    }
}
