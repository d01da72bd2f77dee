//! A disk under any affine map: Mitsuba 3's `disk` stretched (or sheared)
//! into an ellipse by its `to_world` (src/shapes/disk.cpp: the unit disk at
//! z = 0 carried by the transform, its normal `to_world`'s image of +z as
//! a normal, that is by the inverse transpose). A disk scaled evenly stays
//! a [`super::Disk`].

use super::{ShapeHit, FLAT};
use crate::math::{gamma, Ray, Vertex};
use glam::{DAffine3, Vec3};

/// The points c + x a + y b with x² + y² ≤ 1. Kept as the centre, the unit
/// normal and the dual axes `u`, `v` (x = u · (p - c), y = v · (p - c) for
/// a point p of the plane): what a ray test needs, in 48 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipse {
    pub center: Vertex,
    pub normal: Vec3,
    u: Vec3,
    v: Vec3,
}

impl Ellipse {
    /// The image of the unit disk under `to_world`; `None` where the map
    /// flattens it or is not finite.
    pub fn new(to_world: &DAffine3) -> Option<Self> {
        let inv = to_world.inverse();
        let rows = inv.matrix3.transpose();
        let normal = rows.z_axis.try_normalize()?;
        let e = Ellipse {
            center: to_world.translation.as_vec3(),
            normal: normal.as_vec3(),
            u: rows.x_axis.as_vec3(),
            v: rows.y_axis.as_vec3(),
        };
        let (a, b) = e.axes();
        (to_world.matrix3.determinant() != 0.0 && [e.center, e.u, e.v, a, b].iter().all(|x| x.is_finite())).then_some(e)
    }

    /// The same ellipse facing the other way (Mitsuba's `flip_normals`).
    pub fn flipped(self) -> Self {
        Ellipse { normal: -self.normal, ..self }
    }

    /// The semi-axes a and b (the images of the unit disk's x and y): a
    /// lies in the plane with u · a = 1 and v · a = 0, b likewise.
    pub fn axes(&self) -> (Vec3, Vec3) {
        let (u, v, n) = (self.u.as_dvec3(), self.v.as_dvec3(), self.normal.as_dvec3());
        let a = v.cross(n);
        let b = n.cross(u);
        ((a / a.dot(u)).as_vec3(), (b / b.dot(v)).as_vec3())
    }

    pub fn area(&self) -> f32 {
        let (a, b) = self.axes();
        std::f32::consts::PI * a.cross(b).length()
    }

    #[inline]
    pub fn distance(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let denom = ray.dir.dot(self.normal);
        if denom == 0.0 {
            return None;
        }
        let t = (self.center - ray.origin).dot(self.normal) / denom;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let q = ray.at(t) - self.center;
        let (x, y) = (self.u.dot(q), self.v.dot(q));
        (x * x + y * y <= 1.0).then_some(t)
    }

    pub fn record(&self, ray: &Ray, t: f32) -> ShapeHit {
        let local = ray.at(t) - self.center;
        // Onto the plane exactly (removes the error along the normal).
        let local = local - self.normal * local.dot(self.normal);
        let point = self.center + local;
        let p_err = gamma(6) * (local.abs() + self.center.abs() + point.abs());
        ShapeHit { t, point, p_err, normal: self.normal, uv: [0.0; 2], shading: FLAT, shading_normal: None }
    }

    /// The least and greatest `x . w` over the ellipse: c · w ± |(a · w, b · w)|.
    pub fn extent_along(&self, w: Vec3) -> (f32, f32) {
        let (a, b) = self.axes();
        let half = (a.dot(w).powi(2) + b.dot(w).powi(2)).sqrt();
        let c = self.center.dot(w);
        (c - half, c + half)
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        let (a, b) = self.axes();
        let e = (a * a + b * b).sqrt();
        (self.center - e, self.center + e)
    }

    /// A sphere holding the ellipse: the centre, and the longer axis bounded
    /// by |a|² + |b|².
    pub fn bounding_sphere(&self) -> (Vertex, f32) {
        let (a, b) = self.axes();
        (self.center, (a.length_squared() + b.length_squared()).sqrt())
    }

    /// The ellipse with every length times `s` about the origin.
    pub fn scaled(&self, s: f32) -> Self {
        Ellipse { center: self.center * s, normal: self.normal, u: self.u / s, v: self.v / s }
    }
}

/// The affine map of the unit disk onto the ellipse (columns a, b, the
/// normal, the centre): what Mitsuba's `disk` takes as `to_world`.
pub fn ellipse_to_world(e: &Ellipse) -> DAffine3 {
    let (a, b) = e.axes();
    DAffine3::from_cols(a.as_dvec3(), b.as_dvec3(), e.normal.as_dvec3(), e.center.as_dvec3())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DMat3, DVec3};

    fn stretched() -> (DAffine3, Ellipse) {
        let m = DAffine3::from_translation(DVec3::new(1.0, 2.0, 3.0))
            * DAffine3::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.8)
            * DAffine3::from_scale(DVec3::new(1.5, 2.5, 1.0));
        (m, Ellipse::new(&m).unwrap())
    }

    /// Points of the unit disk carried by the map are hit, points just
    /// outside it are not; the normal is the map's image of +z as a normal.
    #[test]
    fn an_ellipse_is_the_image_of_the_unit_disk() {
        let (m, e) = stretched();
        let n = (m.matrix3.inverse().transpose() * DVec3::Z).normalize().as_vec3();
        assert!((e.normal - n).length() < 1e-6);
        for i in 0..32 {
            let phi = i as f64 * std::f64::consts::TAU / 32.0;
            for (r, hit) in [(0.98, true), (1.02, false), (0.0, true)] {
                let p = m.transform_point3(DVec3::new(r * phi.cos(), r * phi.sin(), 0.0)).as_vec3();
                let ray = Ray::new(p + 3.0 * n + 0.2 * e.axes().0, -(3.0 * n + 0.2 * e.axes().0).normalize());
                let h = e.distance(&ray, f32::INFINITY);
                assert_eq!(h.is_some(), hit, "r {r}, phi {phi}");
                if let Some(t) = h {
                    assert!((e.record(&ray, t).point - p).length() < 1e-4);
                }
            }
        }
        let (a, b) = e.axes();
        let want = std::f32::consts::PI * 1.5 * 2.5;
        assert!((e.area() - want).abs() < 1e-4 * want, "{}", e.area());
        assert!((a.length() - 1.5).abs() < 1e-5 && (b.length() - 2.5).abs() < 1e-5);
        // Flat maps have no ellipse.
        assert!(Ellipse::new(&DAffine3::from_mat3(DMat3::from_diagonal(DVec3::new(1.0, 0.0, 1.0)))).is_none());
    }

    /// The bounds, the sphere and the extents hold the rim; the extent is
    /// reached.
    #[test]
    fn bounds_hold_the_rim() {
        let (m, e) = stretched();
        let (lo, hi) = e.bounds();
        let (c, r) = e.bounding_sphere();
        let w = Vec3::new(0.3, -0.5, 0.8).normalize();
        let (a, b) = e.extent_along(w);
        let (mut least, mut most) = (f32::INFINITY, f32::NEG_INFINITY);
        for i in 0..4096 {
            let phi = i as f64 * std::f64::consts::TAU / 4096.0;
            let p = m.transform_point3(DVec3::new(phi.cos(), phi.sin(), 0.0)).as_vec3();
            assert!(p.cmpge(lo - 1e-5).all() && p.cmple(hi + 1e-5).all());
            assert!((p - c).length() <= r + 1e-5);
            least = least.min(p.dot(w));
            most = most.max(p.dot(w));
        }
        assert!((least - a).abs() < 1e-3 && (most - b).abs() < 1e-3, "{least} {most} vs {a} {b}");
        let back = ellipse_to_world(&e);
        assert!((back.transform_point3(DVec3::X) - m.transform_point3(DVec3::X)).length() < 1e-5);
    }
}
