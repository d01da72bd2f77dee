//! The CS475 assignment's transformed unit sphere (an ellipsoid under a
//! non-uniform scale).

use super::{ShapeHit, Sphere, FLAT};
use crate::math::{gamma, Ray};
use glam::{Affine3, Affine3A, Vec3};

/// The assignment's transformed unit sphere: a transform maps the unit
/// sphere at the origin onto the shape (an ellipsoid under non-uniform
/// scale). A ray is carried into object space, met there by the unit
/// sphere, and the hit's normal is carried back by the inverse transpose.
///
/// Only the inverse is kept (48 bytes, not SIMD-aligned), so that a
/// primitive of the scene stays small: every triangle is as large as the
/// largest shape. The forward map is rebuilt where a hit is recorded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipsoid {
    to_object: Affine3,
    /// The normal points inwards (Mitsuba's `flip_normals`).
    flip: bool,
}

impl Ellipsoid {
    /// `None` when the transform is singular (it would flatten the sphere).
    pub fn new(to_world: Affine3A) -> Option<Self> {
        let det = to_world.matrix3.determinant();
        if !(det.abs() > 0.0) || !to_world.is_finite() {
            return None;
        }
        let to_object = to_world.inverse();
        let to_object = Affine3::from_mat3_translation(to_object.matrix3.into(), to_object.translation.into());
        (to_object.is_finite() && to_object.inverse().is_finite()).then_some(Ellipsoid { to_object, flip: false })
    }

    /// The same surface with its normal pointing inwards.
    pub fn flipped(self) -> Self {
        Ellipsoid { flip: !self.flip, ..self }
    }

    /// Whether the normal points inwards.
    pub fn is_flipped(&self) -> bool {
        self.flip
    }

    /// The ellipsoid with every length times `s` about the origin.
    pub fn scaled(&self, s: f32) -> Self {
        Ellipsoid::new(Affine3A::from_scale(Vec3::splat(s)) * self.to_world())
            .map_or(*self, |e| Ellipsoid { flip: self.flip, ..e })
    }

    /// The map from the unit sphere to the shape.
    pub fn to_world(&self) -> Affine3A {
        let w = self.to_object.inverse();
        Affine3A::from_mat3_translation(w.matrix3, w.translation)
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
        // Leaving along a flipped normal is leaving the unit sphere inwards.
        let departed = departed.map(|along| along != self.flip);
        // The affine map keeps a line's parameter; only the unit-length
        // normalisation in object space rescales it.
        unit.distance(&local, t_max * len, departed).map(|t| t / len)
    }

    pub fn record(&self, ray: &Ray, t: f32) -> ShapeHit {
        let (local_ray, len) = self.object_ray(ray).unwrap_or((*ray, 1.0));
        let unit = Sphere { center: Vec3::ZERO, radius: 1.0 }.record(&local_ray, t * len);
        let local = unit.point;
        let to_world = self.to_world();
        let point = to_world.transform_point3(local);
        let m = to_world.matrix3;
        let abs_m = glam::Mat3A::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        // The object point's error carried through the matrix, plus the
        // rounding of the matrix product and the translation.
        let p_err = Vec3::from(abs_m * glam::Vec3A::from(unit.p_err + gamma(4) * local.abs()))
            + gamma(4) * (Vec3::from(abs_m * glam::Vec3A::from(local.abs())) + Vec3::from(to_world.translation.abs()));
        let normal = (self.to_object.matrix3.transpose() * local).normalize();
        let normal = if self.flip { -normal } else { normal };
        ShapeHit { t, point, p_err, normal, uv: [0.0; 2], shading: FLAT, shading_normal: None }
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        // Extent along axis i of the image of the unit sphere: |row i of M|.
        let to_world = self.to_world();
        let m = to_world.matrix3.transpose();
        let e = Vec3::new(m.x_axis.length(), m.y_axis.length(), m.z_axis.length());
        let c = Vec3::from(to_world.translation);
        (c - e, c + e)
    }
}
