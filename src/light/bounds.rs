//! What bounds the light a light or a cluster of lights sends: box, power
//! and the cone of directions it emits into, as the light hierarchy
//! ([`super::sampler`]) stores at its nodes (Conty Estévez and Kulla 2018;
//! pbrt-v4 §12.6.3, the cone union of §3.8.4).

use glam::Vec3;
use std::f32::consts::PI;

/// What bounds the light of one light or a cluster of them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    pub lo: Vec3,
    pub hi: Vec3,
    /// Power (largest channel).
    pub phi: f32,
    /// The axis of the cone of normals (or emission axes).
    pub w: Vec3,
    /// Cosine of the cone's half-angle θo (-1: every direction).
    pub cos_o: f32,
    /// Cosine of the angle θe beyond the cone into which light still
    /// leaves (0 for a Lambertian surface: π/2).
    pub cos_e: f32,
}

impl LightBounds {
    /// Bounds of both.
    pub fn union(&self, other: &LightBounds) -> LightBounds {
        let (w, cos_o) = union_cone((self.w, self.cos_o), (other.w, other.cos_o));
        LightBounds {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
            phi: self.phi + other.phi,
            w,
            cos_o,
            cos_e: self.cos_e.min(other.cos_e),
        }
    }

    /// pbrt-v4's cost of a cluster for the build: power times the solid
    /// angle measure of its directions M_Ω times its box's area, stretched
    /// by how thin the box is along the split's axis.
    pub(super) fn cost(&self, thinness: f32) -> f32 {
        let theta_o = self.cos_o.clamp(-1.0, 1.0).acos();
        let theta_e = self.cos_e.clamp(-1.0, 1.0).acos();
        let theta_w = (theta_o + theta_e).min(PI);
        let sin_o = theta_o.sin();
        let m_omega = 2.0 * PI * (1.0 - self.cos_o)
            + PI / 2.0 * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o + self.cos_o);
        let d = self.hi - self.lo;
        let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
        self.phi * m_omega * thinness * area.max(f32::MIN_POSITIVE)
    }
}

/// The angle between unit vectors, accurate for small and large ones.
pub(super) fn angle_between(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) < 0.0 {
        PI - 2.0 * ((a + b).length() * 0.5).min(1.0).asin()
    } else {
        2.0 * ((b - a).length() * 0.5).min(1.0).asin()
    }
}

/// The smallest cone (axis, cosine of its half-angle) holding both cones,
/// widened by 1e-4 radian against rounding (pbrt-v4 §3.8.4).
pub(super) fn union_cone(a: (Vec3, f32), b: (Vec3, f32)) -> (Vec3, f32) {
    // The common case of a flat emitter: one axis.
    if a.0 == b.0 {
        return (a.0, a.1.min(b.1));
    }
    let (theta_a, theta_b) = (a.1.clamp(-1.0, 1.0).acos(), b.1.clamp(-1.0, 1.0).acos());
    let theta_d = angle_between(a.0, b.0);
    if (theta_d + theta_b).min(PI) <= theta_a {
        return a;
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return b;
    }
    let theta_o = (theta_a + theta_d + theta_b) * 0.5 + 1e-4;
    let axis = a.0.cross(b.0);
    if theta_o >= PI || axis.length_squared() == 0.0 {
        return (a.0, -1.0);
    }
    // Rotate a's axis towards b's by θo - θa (Rodrigues; the rotation axis
    // is perpendicular to it).
    let k = axis.normalize();
    let r = theta_o - theta_a;
    let w = (a.0 * r.cos() + k.cross(a.0) * r.sin()).normalize();
    (w, theta_o.cos())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, uniform_cone, Domain};

    #[test]
    fn a_cone_union_holds_both_cones() {
        let mut rng = stream(6, Domain::Camera, 3);
        for _ in 0..10_000 {
            let a = (uniform_cone(next_2d(&mut rng), -1.0).normalize(), next_2d(&mut rng).x * 2.0 - 1.0);
            let b = (uniform_cone(next_2d(&mut rng), -1.0).normalize(), next_2d(&mut rng).x * 2.0 - 1.0);
            let (w, c) = union_cone(a, b);
            for (axis, cos) in [a, b] {
                // The cone's rim directions lie inside the union.
                let f = crate::math::Frame::from_normal(axis);
                for k in 0..16 {
                    let phi = k as f32 / 16.0 * 2.0 * PI;
                    let s = (1.0 - cos * cos).max(0.0).sqrt();
                    let d = f.to_world(Vec3::new(s * phi.cos(), s * phi.sin(), cos));
                    assert!(d.dot(w) >= c - 1e-5, "{a:?} {b:?} -> {w} {c}: {d}");
                }
            }
        }
    }
}
