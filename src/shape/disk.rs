//! Flat disks (the default scene's light, and disk shapes).

use super::{ShapeHit, FLAT};
use crate::math::{gamma, Ray, Vertex};
use glam::Vec3;

/// A flat disk with unit `normal`; one-sided emission is the light's concern,
/// geometry is hit from both sides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    pub center: Vertex,
    pub normal: Vec3,
    pub radius: f32,
}

impl Disk {
    /// The transform taking Mitsuba's unit disk (normal +z) to this one
    /// (its tangents from the normal's frame).
    pub fn to_world(&self) -> glam::Affine3A {
        let f = crate::math::Frame::from_normal(self.normal);
        let r = self.radius;
        glam::Affine3A::from_cols((f.s * r).into(), (f.t * r).into(), (f.n * r).into(), self.center.into())
    }

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
        ShapeHit { t, point, p_err, normal: self.normal, uv: [0.0; 2], shading: FLAT, shading_normal: None }
    }

    pub fn area(&self) -> f32 {
        std::f32::consts::PI * self.radius * self.radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray::new(Vec3::from(o), Vec3::from(d).normalize())
    }

    #[test]
    fn disk_hit_and_rim() {
        let d = Disk { center: Vec3::new(8.0, 0.0, 4.999), normal: -Vec3::Z, radius: 1.0 };
        assert!(d.intersect(&ray([8.5, 0.5, 0.0], [0.0, 0.0, 1.0]), f32::MAX).is_some());
        assert!(d.intersect(&ray([8.8, 0.8, 0.0], [0.0, 0.0, 1.0]), f32::MAX).is_none());
        assert!((d.area() - std::f32::consts::PI).abs() < 1e-6);
    }
}
