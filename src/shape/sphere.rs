//! Spheres, met analytically at both roots.

use super::{ShapeHit, FLAT};
use crate::math::{gamma, Ray, Vertex};
use glam::Vec3;

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
        ShapeHit { t, point, p_err, normal: local / self.radius, uv: [0.0; 2], shading: FLAT, shading_normal: None }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray::new(Vec3::from(o), Vec3::from(d).normalize())
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
}
