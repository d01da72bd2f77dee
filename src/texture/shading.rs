//! Shading frames from texture coordinates, and the normal and bump maps
//! that bend them, as Mitsuba 3 defines them: a surface's tangents are
//! the derivatives of position by texture coordinates (dp/du, dp/dv; a
//! mesh without coordinates takes its normal's `coordinate_system`), the
//! shading frame's first axis is dp/du made perpendicular to the normal
//! (mesh.cpp, sphere.cpp, ...). A normal map (normalmap.cpp) replaces the
//! normal by 2 t - 1 of its RGB texture in that frame; a bump map
//! (bumpmap.cpp) displaces the surface along the normal by `scale` times
//! its texture and takes the normal of the displaced surface.

use super::{SurfacePoint, SurfaceUv, Texture};
use crate::shape::Shape;
use glam::{Affine3A, Vec2, Vec3};
use std::f32::consts::PI;

/// How a material bends the shading normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Perturb {
    /// Texture number `n` holds tangent-space normals.
    NormalMap(u32),
    /// Texture `texture` holds heights, times `scale`.
    BumpMap { texture: u32, scale: f32 },
}

/// dp/du and dp/dv of `shape` at world `point`, parametrised by `uv`.
pub fn tangents(uv: &SurfaceUv, shape: &Shape, point: Vec3, frames: &[Affine3A]) -> (Vec3, Vec3) {
    let to_world = |i: u32| frames.get(i as usize).map(|f| f.inverse());
    match (*uv, shape) {
        (SurfaceUv::Triangle(t), Shape::Triangle(tri)) => {
            let (dp1, dp2) = (tri.v1 - tri.v0, tri.v2 - tri.v0);
            let (d1, d2) = (t[1] - t[0], t[2] - t[0]);
            let det = d1.x * d2.y - d1.y * d2.x;
            if det.abs() > 1e-20 {
                let inv = 1.0 / det;
                return ((d2.y * dp1 - d1.y * dp2) * inv, (d1.x * dp2 - d2.x * dp1) * inv);
            }
            coordinate_system(tri.normal)
        }
        (SurfaceUv::Sphere(i), _) | (SurfaceUv::Cylinder(i), _) | (SurfaceUv::Disk(i), _) => {
            let Some(m) = to_world(i) else { return coordinate_system(Vec3::Z) };
            let p = frames[i as usize].transform_point3(point);
            let (du, dv) = match uv {
                SurfaceUv::Sphere(_) => {
                    let p = p.normalize_or_zero();
                    let rho = p.truncate().length();
                    let (cos_phi, sin_phi) = if rho > 0.0 { (p.x / rho, p.y / rho) } else { (1.0, 0.0) };
                    (2.0 * PI * Vec3::new(-p.y, p.x, 0.0), PI * Vec3::new(p.z * cos_phi, p.z * sin_phi, -rho))
                }
                SurfaceUv::Cylinder(_) => (2.0 * PI * Vec3::new(-p.y, p.x, 0.0), Vec3::Z),
                _ => {
                    let r = p.truncate().length();
                    let dir = if r > 0.0 { p.truncate() / r } else { Vec2::X };
                    (dir.extend(0.0), 2.0 * PI * Vec3::new(-p.y, p.x, 0.0))
                }
            };
            (m.transform_vector3(du), m.transform_vector3(dv))
        }
        (_, s) => {
            let n = match s {
                Shape::Triangle(t) => t.normal,
                _ => Vec3::Z,
            };
            coordinate_system(n)
        }
    }
}

/// Mitsuba's `coordinate_system` (Duff et al. 2017).
fn coordinate_system(n: Vec3) -> (Vec3, Vec3) {
    let f = crate::math::Frame::from_normal(n);
    (f.s, f.t)
}

/// The unit tangent dp/du makes in the plane of unit normal `n`.
#[inline]
pub fn tangent_of(n: Vec3, dp_du: Vec3) -> Vec3 {
    (dp_du - n * n.dot(dp_du)).try_normalize().unwrap_or_else(|| coordinate_system(n).0)
}

impl Perturb {
    /// The bent shading normal and its tangent, from the shading normal
    /// `n`, the geometric normal `ng` and the surface's tangents; `None`
    /// where the map gives no usable normal.
    pub fn apply(
        &self,
        at: &SurfacePoint,
        textures: &[Texture],
        n: Vec3,
        ng: Vec3,
        (dp_du, dp_dv): (Vec3, Vec3),
    ) -> Option<(Vec3, Vec3)> {
        let bent = match *self {
            Perturb::NormalMap(i) => {
                let local = textures[i as usize].eval(at) * 2.0 - 1.0;
                let s = tangent_of(n, dp_du);
                let t = n.cross(s);
                (s * local.x + t * local.y + n * local.z).try_normalize()?
            }
            Perturb::BumpMap { texture, scale } => {
                let grad = textures[texture as usize].eval_1_grad(at) * scale;
                let du = dp_du + n * (grad.x - n.dot(dp_du));
                let dv = dp_dv + n * (grad.y - n.dot(dp_dv));
                let m = du.cross(dv).try_normalize()?;
                if m.dot(ng) < 0.0 {
                    -m
                } else {
                    m
                }
            }
        };
        Some((bent, tangent_of(bent, dp_du)))
    }
}
