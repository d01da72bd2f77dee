//! Texture coordinates over a primitive, as Mitsuba 3 parametrises its
//! shapes (src/shapes/*.cpp): a mesh's per-vertex coordinates interpolated
//! (its barycentrics where it has none), a sphere's (phi / 2 pi, theta / pi)
//! about its own z axis, a disk's (r, phi / 2 pi), a cylinder's
//! (phi / 2 pi, z), each in the shape's own frame.

use glam::{Affine3A, Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SurfaceUv {
    /// A triangle without coordinates of its own.
    Barycentric,
    /// A triangle's coordinates at its three corners.
    Triangle([Vec2; 3]),
    /// The analytic shapes, by the index of their world-to-object transform.
    Sphere(u32),
    Disk(u32),
    Cylinder(u32),
}

impl SurfaceUv {
    /// The coordinates at world-space `point`, barycentrics `bary` (of the
    /// second and third corners), given the shapes' world-to-object
    /// transforms.
    #[inline]
    pub fn uv(&self, point: Vec3, bary: Vec2, frames: &[Affine3A]) -> Vec2 {
        let local = |i: u32| frames.get(i as usize).map_or(Vec3::ZERO, |f| f.transform_point3(point));
        let turn = |y: f32, x: f32| {
            let phi = y.atan2(x);
            if phi < 0.0 {
                phi + 2.0 * PI
            } else {
                phi
            }
        };
        match *self {
            SurfaceUv::Barycentric => bary,
            SurfaceUv::Triangle(t) => t[0] * (1.0 - bary.x - bary.y) + t[1] * bary.x + t[2] * bary.y,
            SurfaceUv::Sphere(i) => {
                let p = local(i).normalize_or_zero();
                let theta = p.z.clamp(-1.0, 1.0).acos();
                Vec2::new(turn(p.y, p.x) / (2.0 * PI), theta * FRAC_1_PI)
            }
            SurfaceUv::Disk(i) => {
                let p = local(i);
                Vec2::new(p.truncate().length(), turn(p.y, p.x) / (2.0 * PI))
            }
            SurfaceUv::Cylinder(i) => {
                let p = local(i);
                Vec2::new(turn(p.y, p.x) / (2.0 * PI), p.z)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analytic_shapes_map_as_mitsuba_does() {
        // A unit sphere at (1, 2, 3) turned a quarter about z.
        let to_world = Affine3A::from_translation(Vec3::new(1.0, 2.0, 3.0)) * Affine3A::from_rotation_z(PI / 2.0);
        let frames = [to_world.inverse()];
        let at = |uv: SurfaceUv, p: Vec3| uv.uv(to_world.transform_point3(p), Vec2::ZERO, &frames);
        let north = at(SurfaceUv::Sphere(0), Vec3::Z);
        assert!(north.y.abs() < 1e-6);
        let y = at(SurfaceUv::Sphere(0), Vec3::Y);
        assert!((y - Vec2::new(0.25, 0.5)).length() < 1e-6, "{y}");
        let disk = at(SurfaceUv::Disk(0), Vec3::new(0.0, -0.5, 0.0));
        assert!((disk - Vec2::new(0.5, 0.75)).length() < 1e-6, "{disk}");
        let tube = at(SurfaceUv::Cylinder(0), Vec3::new(-1.0, 0.0, 0.3));
        assert!((tube - Vec2::new(0.5, 0.3)).length() < 1e-6, "{tube}");
        let t = SurfaceUv::Triangle([Vec2::ZERO, Vec2::X, Vec2::Y]);
        assert_eq!(t.uv(Vec3::ZERO, Vec2::new(0.25, 0.5), &frames), Vec2::new(0.25, 0.5));
    }
}
