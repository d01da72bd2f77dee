//! Triangles: the watertight ray test the renderer uses (Woop, Benthin &
//! Wald) and the course's Möller–Trumbore, and tetrahedra as four of them.

use super::ShapeHit;
use crate::math::{gamma, Ray, Vertex};
use glam::Vec3;

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

/// A triangle with vertices `v0, v1, v2`; its normal is `(v1-v0) x (v2-v0)`
/// normalised. Degenerate (zero-area) triangles are never hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    pub v0: Vertex,
    pub v1: Vertex,
    pub v2: Vertex,
    pub normal: Vec3,
    /// The scene's vertex normals of this triangle (an index into
    /// [`crate::scene::Scene`]'s table), or [`FLAT`]: shaded with `normal`.
    pub shading: u32,
}

/// A triangle shaded with its geometric normal.
pub const FLAT: u32 = u32::MAX;

impl Triangle {
    pub fn new(v0: Vertex, v1: Vertex, v2: Vertex) -> Self {
        let normal = (v1 - v0).cross(v2 - v0).try_normalize().unwrap_or(Vec3::ZERO);
        Triangle { v0, v1, v2, normal, shading: FLAT }
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
        let (e1, e2) = (self.v1 - self.v0, self.v2 - self.v0);
        let p = ray.dir.cross(e2);
        let det = p.dot(e1);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv = 1.0 / det;
        let tv = ray.origin - self.v0;
        let u = p.dot(tv) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = tv.cross(e1);
        let v = q.dot(ray.dir) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = q.dot(e2) * inv;
        (t > 0.0 && t < t_max).then_some((t, u, v))
    }

    /// The hit record at barycentric (u, v): the barycentric form of the point
    /// is more accurate than o + t d, and its error is bounded by gamma(7)
    /// times the sum of the weighted vertex magnitudes.
    pub fn record(&self, t: f32, u: f32, v: f32) -> ShapeHit {
        let w = 1.0 - u - v;
        let point = w * self.v0 + u * self.v1 + v * self.v2;
        let p_err = gamma(7) * ((w * self.v0).abs() + (u * self.v1).abs() + (v * self.v2).abs());
        ShapeHit { t, point, p_err, normal: self.normal, uv: [u, v], shading: self.shading, shading_normal: None }
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
}
