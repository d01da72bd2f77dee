//! The course's shapes: triangles (Möller–Trumbore), spheres (analytic, both
//! roots), disks, and tetrahedra as four triangles.
//!
//! Every intersection returns the hit point together with a bound on its
//! rounding error, which [`crate::math::offset_ray_origin`] turns into a safe
//! origin for the next ray. A ray leaving a surface also says which primitive
//! it left and to which side ([`Departure`]): a ray can never meet the plane
//! it leaves again, nor the outside of a convex sphere it leaves outwards, and
//! a ray leaving a sphere inwards can only meet its far side. These exact
//! rules replace the "ignore hits closer than epsilon" habit, which also
//! ignores genuinely close surfaces.

use crate::math::{gamma, Ray, Vertex};
use glam::{Affine3A, Vec3};

/// Where a ray started: the primitive it left and whether it left along the
/// primitive's geometric normal (`outward`) or against it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Departure {
    pub prim: u32,
    pub outward: bool,
}

/// What the watertight triangle test needs from a ray, computed once per ray:
/// the axis permutation making the largest direction component z, and the
/// shear that turns the ray into the +z axis.
#[derive(Clone, Copy, Debug)]
pub struct RayShear {
    k: [usize; 3],
    shear: Vec3,
}

impl RayShear {
    pub fn new(ray: &Ray) -> Self {
        let a = ray.dir.abs();
        let kz = if a.x > a.y {
            if a.x > a.z {
                0
            } else {
                2
            }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let k = [(kz + 1) % 3, (kz + 2) % 3, kz];
        let d = Vec3::new(ray.dir[k[0]], ray.dir[k[1]], ray.dir[k[2]]);
        RayShear { k, shear: Vec3::new(-d.x / d.z, -d.y / d.z, 1.0 / d.z) }
    }
}

/// A ray–shape intersection, before the scene attaches the primitive index.
#[derive(Clone, Copy, Debug)]
pub struct ShapeHit {
    pub t: f32,
    pub point: Vertex,
    /// Bound on |computed point - exact point|, per axis.
    pub p_err: Vec3,
    /// Unit geometric normal as the shape defines it (not flipped to face the ray).
    pub normal: Vec3,
}

/// A triangle with vertices `v0, v1, v2`; its normal is `(v1-v0) x (v2-v0)`
/// normalised. Degenerate (zero-area) triangles are never hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    pub v0: Vertex,
    pub v1: Vertex,
    pub v2: Vertex,
    pub normal: Vec3,
    /// Edges v1 - v0 and v2 - v0, kept for Möller–Trumbore.
    e1: Vec3,
    e2: Vec3,
}

impl Triangle {
    pub fn new(v0: Vertex, v1: Vertex, v2: Vertex) -> Self {
        let (e1, e2) = (v1 - v0, v2 - v0);
        let normal = e1.cross(e2).try_normalize().unwrap_or(Vec3::ZERO);
        Triangle { v0, v1, v2, normal, e1, e2 }
    }

    pub fn area(&self) -> f32 {
        0.5 * (self.v1 - self.v0).cross(self.v2 - self.v0).length()
    }

    /// The closest hit in (0, t_max), by the watertight test.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        self.distance(ray, &RayShear::new(ray), t_max).map(|(t, u, v)| self.record(t, u, v))
    }

    /// The distance and barycentric (u, v) of a hit in (0, t_max): Woop,
    /// Benthin & Wald's watertight test (JCGT 2013). The vertices are moved
    /// into a frame where the ray runs along +z from the origin; there the
    /// three edge functions are 2D cross products of transformed vertices. A
    /// shared edge's function is computed from the same two transformed
    /// vertices in both of its triangles, so a ray through the edge is never
    /// rejected by both: no ray escapes between neighbours. (Möller–Trumbore
    /// rounds each triangle's barycentrics independently and let 4% of rays
    /// aimed exactly at the room's edges through; see notes/robustness.md.)
    #[inline]
    pub fn distance(&self, ray: &Ray, rs: &RayShear, t_max: f32) -> Option<(f32, f32, f32)> {
        if self.normal == Vec3::ZERO {
            return None;
        }
        // Early out: a plane behind the origin or beyond t_max cannot hold
        // the hit. The test is conservative by the rounding bound of its two
        // dot products, so it never rejects what the exact test would accept
        // and the watertight decision below stays the only one near edges.
        let to_plane = (self.v0 - ray.origin).dot(self.normal);
        let along = ray.dir.dot(self.normal);
        let slack = gamma(6) * (self.v0.abs() + ray.origin.abs()).dot(self.normal.abs());
        // Signed so that a plane ahead of the origin is positive.
        let (ahead, speed) = if along >= 0.0 { (to_plane, along) } else { (-to_plane, -along) };
        if ahead < -slack || ahead > speed * t_max * (1.0 + gamma(4)) + slack {
            return None;
        }
        // One specialisation per dominant axis: the permutation is then a
        // compile-time shuffle, not three indexed loads.
        match rs.k[2] {
            0 => self.distance_in::<1, 2, 0>(ray, rs, t_max),
            1 => self.distance_in::<2, 0, 1>(ray, rs, t_max),
            _ => self.distance_in::<0, 1, 2>(ray, rs, t_max),
        }
    }

    #[inline(always)]
    fn distance_in<const KX: usize, const KY: usize, const KZ: usize>(
        &self,
        ray: &Ray,
        rs: &RayShear,
        t_max: f32,
    ) -> Option<(f32, f32, f32)> {
        let shear = |p: Vertex| {
            let q = (p - ray.origin).to_array();
            let z = q[KZ];
            Vec3::new(q[KX] + rs.shear.x * z, q[KY] + rs.shear.y * z, z)
        };
        let (p0, p1, p2) = (shear(self.v0), shear(self.v1), shear(self.v2));
        let mut e0 = p1.x * p2.y - p1.y * p2.x;
        let mut e1 = p2.x * p0.y - p2.y * p0.x;
        let mut e2 = p0.x * p1.y - p0.y * p1.x;
        // On an edge exactly: decide in f64, where the products are exact.
        if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
            let x = |a: Vec3, b: Vec3| (a.x as f64 * b.y as f64 - a.y as f64 * b.x as f64) as f32;
            e0 = x(p1, p2);
            e1 = x(p2, p0);
            e2 = x(p0, p1);
        }
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let sz = rs.shear.z;
        let t_scaled = e0 * (p0.z * sz) + e1 * (p1.z * sz) + e2 * (p2.z * sz);
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
            return None;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
            return None;
        }
        let inv = 1.0 / det;
        let t = t_scaled * inv;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        // Barycentric weights of v1 and v2 (e1 is the edge opposite v1, e2 opposite v2).
        Some((t, e1 * inv, e2 * inv))
    }

    /// Möller–Trumbore (TNCG15 lecture 6): solves u E1 + v E2 - t D = T by
    /// Cramer's rule; hits on the edges (u = 0, v = 0, u + v = 1) count.
    /// The course's algorithm, kept for teaching, its tests and the bench
    /// against the watertight test the renderer uses.
    pub fn moller_trumbore(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32, f32)> {
        if self.normal == Vec3::ZERO {
            return None;
        }
        let p = ray.dir.cross(self.e2);
        let det = p.dot(self.e1);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv = 1.0 / det;
        let tv = ray.origin - self.v0;
        let u = p.dot(tv) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = tv.cross(self.e1);
        let v = q.dot(ray.dir) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = q.dot(self.e2) * inv;
        (t > 0.0 && t < t_max).then_some((t, u, v))
    }

    /// The hit record at barycentric (u, v): the barycentric form of the point
    /// is more accurate than o + t d, and its error is bounded by gamma(7)
    /// times the sum of the weighted vertex magnitudes.
    pub fn record(&self, t: f32, u: f32, v: f32) -> ShapeHit {
        let w = 1.0 - u - v;
        let point = w * self.v0 + u * self.v1 + v * self.v2;
        let p_err = gamma(7) * ((w * self.v0).abs() + (u * self.v1).abs() + (v * self.v2).abs());
        ShapeHit { t, point, p_err, normal: self.normal }
    }
}

/// A sphere; its geometric normal points outwards.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vertex,
    pub radius: f32,
}

impl Sphere {
    /// `departed`: `Some(outward)` when the ray leaves this very sphere.
    pub fn intersect(&self, ray: &Ray, t_max: f32, departed: Option<bool>) -> Option<ShapeHit> {
        self.distance(ray, t_max, departed).map(|t| self.record(ray, t))
    }

    /// Distance to the hit in (0, t_max) that the departure rules allow.
    #[inline]
    pub fn distance(&self, ray: &Ray, t_max: f32, departed: Option<bool>) -> Option<f32> {
        if !(self.radius > 0.0) {
            return None;
        }
        // A convex body cannot be met again by a ray leaving its outside.
        if departed == Some(true) {
            return None;
        }
        let oc = ray.origin - self.center;
        let b = oc.dot(ray.dir);
        // Discriminant in the form that avoids cancellation (pbrt-v4 / Ray
        // Tracing Gems ch. 7): r^2 - |oc - b d|^2.
        let f = oc - b * ray.dir;
        let disc = self.radius * self.radius - f.length_squared();
        if disc < 0.0 {
            return None;
        }
        let c = oc.length_squared() - self.radius * self.radius;
        let q = -(b + disc.sqrt().copysign(b));
        let (mut t0, mut t1) = if q == 0.0 { (0.0, 0.0) } else { (q, c / q) };
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        // Leaving inwards: the near root is the departure point itself.
        let t = if departed == Some(false) {
            t1
        } else if t0 > 0.0 {
            t0
        } else {
            t1
        };
        (t > 0.0 && t < t_max).then_some(t)
    }

    /// The hit record at distance `t` (from [`Sphere::distance`]).
    pub fn record(&self, ray: &Ray, t: f32) -> ShapeHit {
        let local = ray.origin + t * ray.dir - self.center;
        let len = local.length();
        // A hit point at the centre needs a zero radius, which never hits.
        let (local, len) = if len > 0.0 {
            (local, len)
        } else {
            let z = Vec3::Z * self.radius;
            (z, z.length())
        };
        // Re-project onto the surface; the error is then a few ulps of the
        // local coordinates plus the rounding of adding the centre back.
        let local = local * (self.radius / len);
        let point = self.center + local;
        let p_err = gamma(5) * local.abs() + gamma(2) * point.abs();
        ShapeHit { t, point, p_err, normal: local / self.radius }
    }
}

/// A flat disk with unit `normal`; one-sided emission is the light's concern,
/// geometry is hit from both sides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    pub center: Vertex,
    pub normal: Vec3,
    pub radius: f32,
}

impl Disk {
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        self.distance(ray, t_max).map(|t| self.record(ray, t))
    }

    #[inline]
    pub fn distance(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let denom = ray.dir.dot(self.normal);
        if denom == 0.0 || !(self.radius > 0.0) {
            return None;
        }
        let t = (self.center - ray.origin).dot(self.normal) / denom;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let local = ray.at(t) - self.center;
        let local = local - self.normal * local.dot(self.normal);
        (local.length_squared() <= self.radius * self.radius).then_some(t)
    }

    pub fn record(&self, ray: &Ray, t: f32) -> ShapeHit {
        let local = ray.at(t) - self.center;
        // Project onto the plane exactly (removes the error along the normal).
        let local = local - self.normal * local.dot(self.normal);
        let point = self.center + local;
        let p_err = gamma(6) * (local.abs() + self.center.abs() + point.abs());
        ShapeHit { t, point, p_err, normal: self.normal }
    }

    pub fn area(&self) -> f32 {
        std::f32::consts::PI * self.radius * self.radius
    }
}

/// The assignment's transformed unit sphere: `to_world` maps the unit sphere
/// at the origin onto the shape (an ellipsoid under non-uniform scale). A ray
/// is carried into object space, met there by the unit sphere, and the hit's
/// normal is carried back by the inverse transpose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipsoid {
    pub to_world: Affine3A,
    to_object: Affine3A,
}

impl Ellipsoid {
    /// `None` when the transform is singular (it would flatten the sphere).
    pub fn new(to_world: Affine3A) -> Option<Self> {
        let det = to_world.matrix3.determinant();
        if !(det.abs() > 0.0) || !to_world.is_finite() {
            return None;
        }
        let to_object = to_world.inverse();
        to_object.is_finite().then_some(Ellipsoid { to_world, to_object })
    }

    /// The ray in object space with a unit direction, and the factor that
    /// turns an object-space distance back into the world ray's parameter.
    #[inline]
    fn object_ray(&self, ray: &Ray) -> Option<(Ray, f32)> {
        let d = self.to_object.transform_vector3(ray.dir);
        let len = d.length();
        if !(len > 0.0) || !len.is_finite() {
            return None;
        }
        Some((Ray::new(self.to_object.transform_point3(ray.origin), d / len), len))
    }

    #[inline]
    pub fn distance(&self, ray: &Ray, t_max: f32, departed: Option<bool>) -> Option<f32> {
        let (local, len) = self.object_ray(ray)?;
        let unit = Sphere { center: Vec3::ZERO, radius: 1.0 };
        // The affine map keeps a line's parameter; only the unit-length
        // normalisation in object space rescales it.
        unit.distance(&local, t_max * len, departed).map(|t| t / len)
    }

    pub fn record(&self, ray: &Ray, t: f32) -> ShapeHit {
        let (local_ray, len) = self.object_ray(ray).unwrap_or((*ray, 1.0));
        let unit = Sphere { center: Vec3::ZERO, radius: 1.0 }.record(&local_ray, t * len);
        let local = unit.point;
        let point = self.to_world.transform_point3(local);
        let m = self.to_world.matrix3;
        let abs_m = glam::Mat3A::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        // The object point's error carried through the matrix, plus the
        // rounding of the matrix product and the translation.
        let p_err = Vec3::from(abs_m * glam::Vec3A::from(unit.p_err + gamma(4) * local.abs()))
            + gamma(4)
                * (Vec3::from(abs_m * glam::Vec3A::from(local.abs())) + Vec3::from(self.to_world.translation.abs()));
        let normal = (self.to_object.matrix3.transpose() * glam::Vec3A::from(local)).normalize();
        ShapeHit { t, point, p_err, normal: Vec3::from(normal) }
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        // Extent along axis i of the image of the unit sphere: |row i of M|.
        let m = self.to_world.matrix3.transpose();
        let e = Vec3::new(m.x_axis.length(), m.y_axis.length(), m.z_axis.length());
        let c = Vec3::from(self.to_world.translation);
        (c - e, c + e)
    }
}

/// The geometry of one primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    Triangle(Triangle),
    Sphere(Sphere),
    Disk(Disk),
    Ellipsoid(Ellipsoid),
}

impl Shape {
    /// Closest intersection in (0, t_max), honouring the departure rules of the
    /// module docs when `departed` is this primitive's own departure.
    pub fn intersect(&self, ray: &Ray, t_max: f32, departed: Option<bool>) -> Option<ShapeHit> {
        self.distance(ray, &std::cell::OnceCell::new(), t_max, departed).map(|(t, uv)| self.record(ray, t, uv))
    }

    /// Distance to the intersection (and the triangle's barycentrics, for
    /// [`Shape::record`]), without building the hit record. `rs` holds the
    /// ray's shear once a triangle has needed it: most rays in a room meet
    /// no triangle's box, and its setup branches on the ray's dominant axis.
    #[inline]
    pub fn distance(
        &self,
        ray: &Ray,
        rs: &std::cell::OnceCell<RayShear>,
        t_max: f32,
        departed: Option<bool>,
    ) -> Option<(f32, [f32; 2])> {
        match self {
            // A ray never meets the plane it leaves again.
            Shape::Triangle(_) | Shape::Disk(_) if departed.is_some() => None,
            Shape::Triangle(tri) => {
                tri.distance(ray, rs.get_or_init(|| RayShear::new(ray)), t_max).map(|(t, u, v)| (t, [u, v]))
            }
            Shape::Disk(disk) => disk.distance(ray, t_max).map(|t| (t, [0.0; 2])),
            Shape::Sphere(s) => s.distance(ray, t_max, departed).map(|t| (t, [0.0; 2])),
            Shape::Ellipsoid(e) => e.distance(ray, t_max, departed).map(|t| (t, [0.0; 2])),
        }
    }

    /// The hit record of a distance found by [`Shape::distance`].
    pub fn record(&self, ray: &Ray, t: f32, uv: [f32; 2]) -> ShapeHit {
        match self {
            Shape::Triangle(tri) => tri.record(t, uv[0], uv[1]),
            Shape::Disk(disk) => disk.record(ray, t),
            Shape::Sphere(s) => s.record(ray, t),
            Shape::Ellipsoid(e) => e.record(ray, t),
        }
    }

    /// Centre and radius of a sphere containing the shape.
    pub fn bounding_sphere(&self) -> (Vertex, f32) {
        match self {
            Shape::Triangle(t) => {
                let c = (t.v0 + t.v1 + t.v2) / 3.0;
                let r = (t.v0 - c).length().max((t.v1 - c).length()).max((t.v2 - c).length());
                (c, r)
            }
            Shape::Sphere(s) => (s.center, s.radius),
            Shape::Disk(d) => (d.center, d.radius),
            Shape::Ellipsoid(e) => {
                let (lo, hi) = e.bounds();
                (Vec3::from(e.to_world.translation), ((hi - lo) * 0.5).length())
            }
        }
    }

    /// The least and greatest value of `x . u` over the shape's points.
    pub fn extent_along(&self, u: Vec3) -> (f32, f32) {
        let (c, half) = match self {
            Shape::Triangle(t) => {
                let (a, b, c) = (t.v0.dot(u), t.v1.dot(u), t.v2.dot(u));
                return (a.min(b).min(c), a.max(b).max(c));
            }
            Shape::Sphere(s) => (s.center.dot(u), s.radius * u.length()),
            // A disk spans r |u - (u.n) n| around its centre.
            Shape::Disk(d) => (d.center.dot(u), d.radius * (u - d.normal * u.dot(d.normal)).length()),
            // x = M y + c over |y| = 1: c.u +- |M^T u|.
            Shape::Ellipsoid(e) => (
                Vec3::from(e.to_world.translation).dot(u),
                (e.to_world.matrix3.transpose() * glam::Vec3A::from(u)).length(),
            ),
        };
        (c - half, c + half)
    }

    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match self {
            Shape::Triangle(t) => (t.v0.min(t.v1).min(t.v2), t.v0.max(t.v1).max(t.v2)),
            Shape::Sphere(s) => (s.center - Vec3::splat(s.radius), s.center + Vec3::splat(s.radius)),
            Shape::Disk(d) => {
                // Extent of a disk along axis i is r * sqrt(1 - n_i^2).
                let e = d.radius * (Vec3::ONE - d.normal * d.normal).max(Vec3::ZERO).sqrt();
                (d.center - e, d.center + e)
            }
            Shape::Ellipsoid(e) => e.bounds(),
        }
    }
}

/// A tetrahedron as four triangles wound so that every normal points out.
pub fn tetrahedron(a: Vertex, b: Vertex, c: Vertex, d: Vertex) -> [Triangle; 4] {
    let centroid = (a + b + c + d) / 4.0;
    let outward = |p: Vertex, q: Vertex, r: Vertex| {
        let t = Triangle::new(p, q, r);
        if t.normal.dot((p + q + r) / 3.0 - centroid) < 0.0 {
            Triangle::new(p, r, q)
        } else {
            t
        }
    };
    [outward(a, b, c), outward(a, b, d), outward(b, c, d), outward(c, a, d)]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray::new(Vec3::from(o), Vec3::from(d).normalize())
    }

    fn unit_triangle() -> Triangle {
        Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)
    }

    #[test]
    fn triangle_hit_reports_distance_point_and_normal() {
        let h = unit_triangle().intersect(&ray([0.2, 0.3, 2.0], [0.0, 0.0, -1.0]), f32::MAX).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        assert!((h.point - Vec3::new(0.2, 0.3, 0.0)).length() < 1e-6);
        assert_eq!(h.normal, Vec3::Z);
        // From below it is hit too (two-sided geometry), same normal.
        let h = unit_triangle().intersect(&ray([0.2, 0.3, -1.0], [0.0, 0.0, 1.0]), f32::MAX).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6);
    }

    #[test]
    fn triangle_miss_outside_the_edges() {
        let tri = unit_triangle();
        for o in [[0.6, 0.6, 1.0], [-0.01, 0.5, 1.0], [0.5, -0.01, 1.0], [2.0, 2.0, 1.0]] {
            assert!(tri.intersect(&ray(o, [0.0, 0.0, -1.0]), f32::MAX).is_none(), "{o:?}");
            assert!(tri.moller_trumbore(&ray(o, [0.0, 0.0, -1.0]), f32::MAX).is_none(), "{o:?}");
        }
    }

    /// Both algorithms agree on distance and barycentrics away from edges.
    #[test]
    fn watertight_test_agrees_with_moller_trumbore() {
        let mut rng = crate::sampling::stream(4, crate::sampling::Domain::Camera, 0);
        let mut both = 0;
        for _ in 0..20_000 {
            let mut p = || {
                Vec3::new(
                    crate::sampling::next_2d(&mut rng).x,
                    crate::sampling::next_2d(&mut rng).y,
                    crate::sampling::next_2d(&mut rng).x,
                ) * 4.0
                    - 2.0
            };
            let tri = Triangle::new(p(), p(), p());
            let o = p() * 3.0;
            // Aim at a point of the triangle's plane near it: most rays hit.
            let w = crate::sampling::next_2d(&mut rng) * 1.2 - 0.1;
            let target = tri.v0 + w.x * (tri.v1 - tri.v0) + w.y * (tri.v2 - tri.v0);
            let Some(d) = (target - o).try_normalize() else { continue };
            let r = Ray::new(o, d);
            match (tri.distance(&r, &RayShear::new(&r), f32::MAX), tri.moller_trumbore(&r, f32::MAX)) {
                (Some(a), Some(b)) => {
                    both += 1;
                    assert!((a.0 - b.0).abs() < 1e-4 * a.0.max(1.0), "{a:?} {b:?}");
                    assert!((a.1 - b.1).abs() < 1e-3 && (a.2 - b.2).abs() < 1e-3, "{a:?} {b:?}");
                }
                (None, None) => {}
                // Only grazing edge cases may differ.
                (a, b) => {
                    let (t, u, v) = a.or(b).unwrap();
                    assert!(u.min(v).min(1.0 - u - v) < 1e-4 || t < 1e-4, "{a:?} {b:?}");
                }
            }
        }
        assert!(both > 5_000, "{both}");
    }

    #[test]
    fn triangle_edges_and_vertices_count_as_hits() {
        let tri = unit_triangle();
        for o in [[0.5, 0.0, 1.0], [0.0, 0.5, 1.0], [0.5, 0.5, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0]] {
            assert!(tri.intersect(&ray(o, [0.0, 0.0, -1.0]), f32::MAX).is_some(), "{o:?}");
            assert!(tri.moller_trumbore(&ray(o, [0.0, 0.0, -1.0]), f32::MAX).is_some(), "{o:?}");
        }
    }

    #[test]
    fn triangle_parallel_behind_and_beyond_t_max_miss() {
        let tri = unit_triangle();
        assert!(tri.moller_trumbore(&ray([0.2, 0.2, 1.0], [0.0, 0.0, 1.0]), f32::MAX).is_none());
        assert!(tri.intersect(&ray([0.2, 0.2, 0.0], [1.0, 0.0, 0.0]), f32::MAX).is_none());
        assert!(tri.intersect(&ray([0.2, 0.2, 1.0], [1.0, 1.0, 0.0]), f32::MAX).is_none());
        assert!(tri.intersect(&ray([0.2, 0.2, 1.0], [0.0, 0.0, 1.0]), f32::MAX).is_none());
        assert!(tri.intersect(&ray([0.2, 0.2, 1.0], [0.0, 0.0, -1.0]), 0.5).is_none());
    }

    #[test]
    fn degenerate_triangles_are_never_hit() {
        let line = Triangle::new(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X);
        let point = Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE);
        for tri in [line, point] {
            assert_eq!(tri.area(), 0.0);
            for d in [[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]] {
                assert!(tri.intersect(&ray([0.5, -1.0, 1.0], d), f32::MAX).is_none());
            }
        }
    }

    #[test]
    fn sphere_from_outside_inside_tangent_and_behind() {
        let s = Sphere { center: Vec3::new(0.0, 0.0, 5.0), radius: 1.0 };
        let h = s.intersect(&ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), f32::MAX, None).unwrap();
        assert!((h.t - 4.0).abs() < 1e-5 && h.normal.dot(Vec3::Z) < -0.999);
        // From the centre: the far root, normal pointing out along the ray.
        let h = s.intersect(&ray([0.0, 0.0, 5.0], [1.0, 0.0, 0.0]), f32::MAX, None).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6 && h.normal.dot(Vec3::X) > 0.999);
        // Tangent: touches at x = 1 exactly.
        let h = s.intersect(&ray([1.0, -3.0, 5.0], [0.0, 1.0, 0.0]), f32::MAX, None).unwrap();
        assert!((h.t - 3.0).abs() < 1e-3 && (h.point - Vec3::new(1.0, 0.0, 5.0)).length() < 1e-3);
        // Just past tangent: a miss.
        assert!(s.intersect(&ray([1.001, -3.0, 5.0], [0.0, 1.0, 0.0]), f32::MAX, None).is_none());
        // Behind the origin.
        assert!(s.intersect(&ray([0.0, 0.0, 0.0], [0.0, 0.0, -1.0]), f32::MAX, None).is_none());
        // Zero radius is never hit.
        let dot = Sphere { center: Vec3::ZERO, radius: 0.0 };
        assert!(dot.intersect(&ray([0.0, 0.0, -1.0], [0.0, 0.0, 1.0]), f32::MAX, None).is_none());
    }

    #[test]
    fn sphere_departure_rules() {
        let s = Sphere { center: Vec3::ZERO, radius: 2.0 };
        let on = Vec3::new(0.0, 0.0, 2.0);
        // Leaving inwards: only the far side, at the chord length.
        let h = s.intersect(&Ray::new(on, -Vec3::Z), f32::MAX, Some(false)).unwrap();
        assert!((h.t - 4.0).abs() < 1e-5);
        // Leaving outwards, even straight back through: nothing.
        assert!(s.intersect(&Ray::new(on, -Vec3::Z), f32::MAX, Some(true)).is_none());
    }

    #[test]
    fn tetrahedron_normals_point_out() {
        let [a, b, c, d] = [
            Vec3::new(10.8, -1.0, -5.0),
            Vec3::new(10.8, 1.0, -5.0),
            Vec3::new(12.4, 0.0, -5.0),
            Vec3::new(11.3, 0.0, -2.5),
        ];
        let centroid = (a + b + c + d) / 4.0;
        for t in tetrahedron(a, b, c, d) {
            assert!(t.normal.dot((t.v0 + t.v1 + t.v2) / 3.0 - centroid) > 0.0);
        }
    }

    #[test]
    fn disk_hit_and_rim() {
        let d = Disk { center: Vec3::new(8.0, 0.0, 4.999), normal: -Vec3::Z, radius: 1.0 };
        assert!(d.intersect(&ray([8.5, 0.5, 0.0], [0.0, 0.0, 1.0]), f32::MAX).is_some());
        assert!(d.intersect(&ray([8.8, 0.8, 0.0], [0.0, 0.0, 1.0]), f32::MAX).is_none());
        assert!((d.area() - std::f32::consts::PI).abs() < 1e-6);
    }
}
