//! A ray's nearest intersection with the scene, and how a path leaves it:
//! the scattering frame, the side a new direction goes to, the adjoint's
//! shading-normal factor, the next ray.

use crate::math::{offset_ray_origin, Frame, Ray, Vertex};
use crate::shape::Departure;
use glam::{Vec2, Vec3};

/// A ray's nearest intersection with the scene.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    pub point: Vertex,
    pub p_err: Vec3,
    /// Geometric normal as the shape defines it.
    pub normal: Vec3,
    /// The normal shading uses: interpolated from a mesh's vertex normals,
    /// else the geometric one. On the geometric normal's side, unit.
    pub shading_normal: Vec3,
    pub prim: u32,
    /// A triangle's barycentric weights of its second and third corners
    /// (zero on other shapes): where textures and attributes are read.
    pub bary: Vec2,
    /// The shading frame's first axis (unit, perpendicular to the shading
    /// normal) where the surface's texture coordinates give one; zero
    /// elsewhere, and the frame is the normal's own.
    pub tangent: Vec3,
}

impl Hit {
    /// The geometric normal turned to the side the ray `dir` arrived from.
    #[inline]
    pub fn facing_normal(&self, dir: Vec3) -> Vec3 {
        if self.normal.dot(dir) < 0.0 {
            self.normal
        } else {
            -self.normal
        }
    }

    /// The frame in which `material` scatters a ray that arrived travelling
    /// along `dir`: the shading normal's, turned to the ray's side (z is the
    /// normal, `-dir` has z > 0); the geometric normal's where there is no
    /// shading normal, or where the shading normal would send the arriving
    /// ray, or a perfect reflection or refraction of it, to the wrong side
    /// of the actual surface (a smooth mesh at grazing angles: light would
    /// leak through it, or be lost). Also whether the ray arrived on the
    /// front of the geometric normal (glass: entering).
    #[inline]
    pub fn scattering_frame(&self, dir: Vec3, material: &crate::material::Material) -> (Frame, bool) {
        let entering = dir.dot(self.normal) < 0.0;
        let geometric = self.facing_normal(dir);
        if self.shading_normal == self.normal {
            return (self.frame_about(geometric), entering);
        }
        let n = if entering { self.shading_normal } else { -self.shading_normal };
        let frame = self.frame_about(n);
        let wo = frame.to_local(-dir);
        let sides_kept = wo.z > 0.0
            && material
                .specular_branches(wo, entering, crate::material::Transport::Radiance)
                .iter()
                .all(|b| (frame.to_world(b.wi).dot(geometric) > 0.0) == (b.wi.z > 0.0));
        if sides_kept {
            (frame, entering)
        } else {
            (self.frame_about(geometric), entering)
        }
    }

    /// The frame about unit normal `n`: along the hit's tangent where it has one.
    #[inline]
    fn frame_about(&self, n: Vec3) -> Frame {
        if self.tangent == Vec3::ZERO {
            return Frame::from_normal(n);
        }
        let s = crate::texture::tangent_of(n, self.tangent);
        Frame { s, t: n.cross(s), n }
    }

    /// Whether unit `dir`, leaving the surface for a ray that arrived along
    /// `arrived`, goes where the scattering said: to the side it arrived
    /// from for a reflection (`reflected`), through for a refraction.
    #[inline]
    pub fn leaves_as(&self, arrived: Vec3, dir: Vec3, reflected: bool) -> bool {
        (dir.dot(self.normal) * arrived.dot(self.normal) < 0.0) == reflected
    }

    /// The factor a photon's power takes, for shading normals, when it
    /// arrives along `arrived` and leaves along `left` (Veach 1997, eq.
    /// 5.21): the adjoint of a BSDF with shading normals is not the BSDF.
    /// 1 where the shading normal is the geometric one.
    #[inline]
    pub fn adjoint_correction(&self, arrived: Vec3, left: Vec3) -> f32 {
        if self.shading_normal == self.normal {
            return 1.0;
        }
        let (ns, ng) = (self.shading_normal, self.normal);
        let denominator = arrived.dot(ng).abs() * left.dot(ns).abs();
        if !(denominator > 0.0) {
            return 0.0;
        }
        arrived.dot(ns).abs() * left.dot(ng).abs() / denominator
    }

    /// A ray leaving this hit along unit `dir`, with its departure record.
    #[inline]
    pub fn spawn(&self, dir: Vec3) -> (Ray, Departure) {
        let origin = offset_ray_origin(self.point, self.p_err, self.normal, dir);
        (Ray::new(origin, dir), Departure { prim: self.prim, outward: dir.dot(self.normal) > 0.0 })
    }
}
