//! Open cylinders, as Mitsuba 3 defines its `cylinder` shape
//! (src/shapes/cylinder.cpp): the tube of a `radius` around the segment
//! from `p0` to `p1`, without end caps, its normal pointing away from the
//! axis unless flipped.
//!
//! The ray is met in double precision: the quadratic's coefficients lose
//! the most digits where an origin lies far from the axis's base point,
//! and a cylinder is a single primitive, so the cost does not matter. The
//! hit point is then projected onto the exact surface in double precision
//! and rounded once, which is what its error bound accounts for.

use super::{ShapeHit, FLAT};
use crate::math::{gamma, Ray, Vertex};
use glam::Vec3;

/// An open cylinder. `axis` is unit length; the geometric normal points
/// away from the axis, or towards it when `flip` is set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    pub p0: Vertex,
    pub axis: Vec3,
    pub length: f32,
    pub radius: f32,
    pub flip: bool,
}

impl Cylinder {
    /// The cylinder around the segment `p0`-`p1`; `None` where the segment
    /// or the radius is empty or not finite.
    pub fn new(p0: Vertex, p1: Vertex, radius: f32, flip: bool) -> Option<Cylinder> {
        let d = p1 - p0;
        let length = d.length();
        let ok = length > 0.0 && length.is_finite() && radius > 0.0 && radius.is_finite() && p0.is_finite();
        ok.then(|| Cylinder { p0, axis: d / length, length, radius, flip })
    }

    pub fn p1(&self) -> Vertex {
        self.p0 + self.axis * self.length
    }

    pub fn intersect(&self, ray: &Ray, t_max: f32, departed: Option<bool>) -> Option<ShapeHit> {
        self.distance(ray, t_max, departed).map(|t| self.record(ray, t))
    }

    /// Distance to the closest hit in (0, t_max). `departed`: `Some(along
    /// the geometric normal)` when the ray leaves this cylinder. The
    /// squared distance from the axis along a line is a convex quadratic:
    /// a ray leaving away from the axis never comes back, and one leaving
    /// towards it meets the tube again only at the other root.
    #[inline]
    pub fn distance(&self, ray: &Ray, t_max: f32, departed: Option<bool>) -> Option<f32> {
        let away = departed.map(|along| along != self.flip);
        if away == Some(true) {
            return None;
        }
        let a = self.axis.as_dvec3().normalize();
        let oc = (ray.origin.as_dvec3() - self.p0.as_dvec3()).reject_from_normalized(a);
        let d = ray.dir.as_dvec3();
        let d_perp = d.reject_from_normalized(a);
        let aa = d_perp.length_squared();
        if !(aa > 0.0) {
            // Parallel to the axis: along the tube, never through it.
            return None;
        }
        let r = self.radius as f64;
        let b = oc.dot(d_perp);
        // The line's closest approach to the axis, without the cancellation
        // of b^2 - a c (as for the sphere: pbrt-v4, Ray Tracing Gems ch. 7).
        let f = oc - (b / aa) * d_perp;
        let disc = r * r - f.length_squared();
        if disc < 0.0 {
            return None;
        }
        let c = oc.length_squared() - r * r;
        let q = -(b + (aa * disc).sqrt().copysign(b));
        let (mut t0, mut t1) = if q == 0.0 { (0.0, 0.0) } else { (q / aa, c / q) };
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        let o = ray.origin.as_dvec3() - self.p0.as_dvec3();
        let within = |t: f64| {
            let h = (o + t * d).dot(a);
            t > 0.0 && t < t_max as f64 && (0.0..=self.length as f64).contains(&h) && (t as f32) > 0.0
        };
        // Leaving towards the axis: the near root is the departure itself.
        let t = if away == Some(false) {
            within(t1).then_some(t1)
        } else if within(t0) {
            Some(t0)
        } else {
            within(t1).then_some(t1)
        }?;
        Some((t as f32).min(t_max.next_down()))
    }

    /// The hit record at distance `t` (from [`Cylinder::distance`]).
    pub fn record(&self, ray: &Ray, t: f32) -> ShapeHit {
        let a = self.axis.as_dvec3().normalize();
        let p0 = self.p0.as_dvec3();
        let local = ray.origin.as_dvec3() + t as f64 * ray.dir.as_dvec3() - p0;
        let h = local.dot(a);
        let radial = local - h * a;
        let len = radial.length();
        // On the axis only a zero radius could be hit, and none is.
        let out = if len > 0.0 { radial / len } else { a.any_orthonormal_vector() };
        let on_surface = h * a + out * self.radius as f64;
        let point = (p0 + on_surface).as_vec3();
        // The double-precision projection is exact to far below one f32
        // ulp of its terms; the bound covers that and the final rounding.
        let p_err = gamma(2) * (point.abs() + self.p0.abs() + on_surface.abs().as_vec3());
        let normal = if self.flip { -out } else { out };
        ShapeHit { t, point, p_err, normal: normal.as_vec3(), uv: [0.0; 2], shading: FLAT, shading_normal: None }
    }

    /// Axis-aligned bounds: the two end circles' boxes.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        // A circle of radius r with normal a spans r sqrt(1 - a_i^2) along axis i.
        let e = self.radius * (Vec3::ONE - self.axis * self.axis).max(Vec3::ZERO).sqrt();
        let p1 = self.p1();
        (self.p0.min(p1) - e, self.p0.max(p1) + e)
    }

    /// Centre and radius of a sphere holding the cylinder.
    pub fn bounding_sphere(&self) -> (Vertex, f32) {
        let half = 0.5 * self.length;
        (self.p0 + self.axis * half, (half * half + self.radius * self.radius).sqrt())
    }

    /// The least and greatest `x . u` over the cylinder.
    pub fn extent_along(&self, u: Vec3) -> (f32, f32) {
        let c = (self.p0 + self.axis * (0.5 * self.length)).dot(u);
        let half = 0.5 * self.length * u.dot(self.axis).abs() + self.radius * u.reject_from(self.axis).length();
        (c - half, c + half)
    }

    pub fn area(&self) -> f32 {
        std::f32::consts::TAU * self.radius * self.length
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray::new(Vec3::from(o), Vec3::from(d).normalize())
    }

    #[test]
    fn a_tube_from_outside_inside_through_its_ends_and_along_its_axis() {
        let c = Cylinder::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0), 1.0, false).unwrap();
        let h = c.intersect(&ray([-3.0, 0.0, 1.0], [1.0, 0.0, 0.0]), f32::MAX, None).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6 && (h.normal + Vec3::X).length() < 1e-6, "{h:?}");
        // From the axis: the wall, normal pointing away from the axis.
        let h = c.intersect(&ray([0.0, 0.0, 1.0], [0.0, 1.0, 0.0]), f32::MAX, None).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6 && (h.normal - Vec3::Y).length() < 1e-6);
        // Past the end: a miss; in through the open end to the far wall.
        assert!(c.intersect(&ray([-3.0, 0.0, 2.5], [1.0, 0.0, 0.0]), f32::MAX, None).is_none());
        let h = c.intersect(&ray([0.0, 0.0, 3.0], [0.6, 0.0, -0.8]), f32::MAX, None).unwrap();
        assert!((h.point - Vec3::new(1.0, 0.0, 3.0 - 4.0 / 3.0)).length() < 1e-5, "{h:?}");
        // Along the axis, and beyond t_max.
        assert!(c.intersect(&ray([0.5, 0.0, -1.0], [0.0, 0.0, 1.0]), f32::MAX, None).is_none());
        assert!(c.intersect(&ray([-3.0, 0.0, 1.0], [1.0, 0.0, 0.0]), 1.9, None).is_none());
        // Flipped, the normal points to the axis.
        let f = Cylinder { flip: true, ..c };
        let h = f.intersect(&ray([-3.0, 0.0, 1.0], [1.0, 0.0, 0.0]), f32::MAX, None).unwrap();
        assert!((h.normal - Vec3::X).length() < 1e-6);
        assert!(Cylinder::new(Vec3::ZERO, Vec3::ZERO, 1.0, false).is_none());
        assert!(Cylinder::new(Vec3::ZERO, Vec3::Z, 0.0, false).is_none());
    }

    #[test]
    fn departures_meet_only_the_far_wall() {
        for flip in [false, true] {
            let c = Cylinder::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0), 1.0, flip).unwrap();
            let on = Vec3::new(1.0, 0.0, 1.0);
            let inward = Ray::new(on, -Vec3::X);
            // Leaving towards the axis is leaving against the outward normal.
            let h = c.intersect(&inward, f32::MAX, Some(flip)).unwrap();
            assert!((h.t - 2.0).abs() < 1e-6);
            assert!(c.intersect(&inward, f32::MAX, Some(!flip)).is_none());
        }
    }

    #[test]
    fn bounds_hold_the_tube() {
        let c = Cylinder::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, -1.0, 5.0), 0.7, false).unwrap();
        let (lo, hi) = c.bounds();
        let (centre, r) = c.bounding_sphere();
        let u = Vec3::new(0.3, -0.5, 0.8).normalize();
        let (a, b) = c.extent_along(u);
        let frame = crate::math::Frame::from_normal(c.axis);
        for i in 0..64 {
            let phi = i as f32 * std::f32::consts::TAU / 64.0;
            for h in [0.0, 0.5, 1.0] {
                let p = c.p0 + c.axis * (h * c.length) + c.radius * (frame.s * phi.cos() + frame.t * phi.sin());
                assert!(p.cmpge(lo - 1e-5).all() && p.cmple(hi + 1e-5).all(), "{p} outside {lo} {hi}");
                assert!((p - centre).length() <= r + 1e-5);
                assert!(p.dot(u) >= a - 1e-5 && p.dot(u) <= b + 1e-5);
            }
        }
    }
}
