//! The course's shapes: triangles (Möller–Trumbore), spheres (analytic, both
//! roots), disks, and tetrahedra as four triangles; ellipsoids, ellipses,
//! Mitsuba's open cylinders and its signed-distance grids.
//!
//! A shape is a closed set: [`Shape`]'s variants, each a file here whose
//! type answers the same few questions (where a ray meets it, the hit's
//! record, its bounds, the scene scaled). Adding one touches its file,
//! its arms in `Shape`'s methods below and the front-end that reads it;
//! nothing past the accelerator matches on shapes, and the Mitsuba export
//! refuses a shape it does not know with its place.
//!
//! Every intersection returns the hit point together with a bound on its
//! rounding error, which [`crate::math::offset_ray_origin`] turns into a safe
//! origin for the next ray. A ray leaving a surface also says which primitive
//! it left and to which side ([`Departure`]): a ray can never meet the plane
//! it leaves again, nor the outside of a convex sphere it leaves outwards, and
//! a ray leaving a sphere inwards can only meet its far side. These exact
//! rules replace the "ignore hits closer than epsilon" habit, which also
//! ignores genuinely close surfaces.

mod cylinder;
mod disk;
mod ellipse;
mod ellipsoid;
mod sdf_grid;
mod sphere;
mod triangle;

pub use cylinder::Cylinder;
pub use disk::Disk;
pub use ellipse::{ellipse_to_world, Ellipse};
pub use ellipsoid::Ellipsoid;
pub use sdf_grid::{Normals, SdfGrid};
pub use sphere::Sphere;
pub use triangle::{tetrahedron, RayShear, Triangle, FLAT};

use crate::math::{Ray, Vertex};
use glam::Vec3;
use std::sync::Arc;

/// Where a ray started: the primitive it left and whether it left along the
/// primitive's geometric normal (`outward`) or against it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Departure {
    pub prim: u32,
    pub outward: bool,
}

/// A ray–shape intersection, before the scene attaches the primitive index.
#[derive(Clone, Copy, Debug)]
pub struct ShapeHit {
    pub t: f32,
    pub point: Vertex,
    /// Bound on |computed point - exact point|, per axis.
    pub p_err: Vec3,
    /// Unit geometric normal as the shape defines it (not flipped to face the ray).
    pub normal: Vec3,
    /// A triangle's barycentric weights of v1 and v2 at the hit (zero for
    /// other shapes).
    pub uv: [f32; 2],
    /// The triangle's vertex normals ([`Triangle::shading`]), or [`FLAT`].
    pub shading: u32,
    /// A shading normal the shape computes itself (on the geometric
    /// normal's side, unit), where it has one: a signed-distance grid's
    /// smooth normals.
    pub shading_normal: Option<Vec3>,
}

/// The geometry of one primitive. Not `Copy`: a grid's samples are shared
/// by reference.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Triangle(Triangle),
    Sphere(Sphere),
    Disk(Disk),
    Ellipsoid(Ellipsoid),
    Cylinder(Cylinder),
    Ellipse(Ellipse),
    SdfGrid(Arc<SdfGrid>),
}

impl Shape {
    /// Closest intersection in (0, t_max), honouring the departure rules of the
    /// module docs when `departed` is this primitive's own departure.
    pub fn intersect(&self, ray: &Ray, t_max: f32, departed: Option<bool>) -> Option<ShapeHit> {
        self.distance(ray, &std::cell::OnceCell::new(), t_max, departed).map(|(t, uv)| self.record(ray, t, uv))
    }

    /// Distance to the intersection (and the triangle's barycentrics, for
    /// [`Shape::record`]), without building the hit record. `rs` holds the
    /// ray's shear once a triangle has needed it: most rays in a room meet
    /// no triangle's box, and its setup branches on the ray's dominant axis.
    #[inline]
    pub fn distance(
        &self,
        ray: &Ray,
        rs: &std::cell::OnceCell<RayShear>,
        t_max: f32,
        departed: Option<bool>,
    ) -> Option<(f32, [f32; 2])> {
        match self {
            // A ray never meets the plane it leaves again.
            Shape::Triangle(_) | Shape::Disk(_) | Shape::Ellipse(_) if departed.is_some() => None,
            Shape::Triangle(tri) => {
                tri.distance(ray, rs.get_or_init(|| RayShear::new(ray)), t_max).map(|(t, u, v)| (t, [u, v]))
            }
            Shape::Disk(disk) => disk.distance(ray, t_max).map(|t| (t, [0.0; 2])),
            Shape::Sphere(s) => s.distance(ray, t_max, departed).map(|t| (t, [0.0; 2])),
            Shape::Ellipsoid(e) => e.distance(ray, t_max, departed).map(|t| (t, [0.0; 2])),
            Shape::Cylinder(c) => c.distance(ray, t_max, departed).map(|t| (t, [0.0; 2])),
            Shape::Ellipse(e) => e.distance(ray, t_max).map(|t| (t, [0.0; 2])),
            Shape::SdfGrid(g) => g.distance(ray, t_max, departed).map(|t| (t, [0.0; 2])),
        }
    }

    /// The hit record of a distance found by [`Shape::distance`].
    pub fn record(&self, ray: &Ray, t: f32, uv: [f32; 2]) -> ShapeHit {
        match self {
            Shape::Triangle(tri) => tri.record(t, uv[0], uv[1]),
            Shape::Disk(disk) => disk.record(ray, t),
            Shape::Sphere(s) => s.record(ray, t),
            Shape::Ellipsoid(e) => e.record(ray, t),
            Shape::Cylinder(c) => c.record(ray, t),
            Shape::Ellipse(e) => e.record(ray, t),
            Shape::SdfGrid(g) => g.record(ray, t),
        }
    }

    /// Centre and radius of a sphere containing the shape.
    pub fn bounding_sphere(&self) -> (Vertex, f32) {
        match self {
            Shape::Triangle(t) => {
                let c = (t.v0 + t.v1 + t.v2) / 3.0;
                let r = (t.v0 - c).length().max((t.v1 - c).length()).max((t.v2 - c).length());
                (c, r)
            }
            Shape::Sphere(s) => (s.center, s.radius),
            Shape::Disk(d) => (d.center, d.radius),
            Shape::Ellipsoid(e) => {
                let (lo, hi) = e.bounds();
                (Vec3::from(e.to_world().translation), ((hi - lo) * 0.5).length())
            }
            Shape::Cylinder(c) => c.bounding_sphere(),
            Shape::Ellipse(e) => e.bounding_sphere(),
            Shape::SdfGrid(g) => g.bounding_sphere(),
        }
    }

    /// The least and greatest value of `x . u` over the shape's points.
    pub fn extent_along(&self, u: Vec3) -> (f32, f32) {
        let (c, half) = match self {
            Shape::Triangle(t) => {
                let (a, b, c) = (t.v0.dot(u), t.v1.dot(u), t.v2.dot(u));
                return (a.min(b).min(c), a.max(b).max(c));
            }
            Shape::Sphere(s) => (s.center.dot(u), s.radius * u.length()),
            // A disk spans r |u - (u.n) n| around its centre.
            Shape::Disk(d) => (d.center.dot(u), d.radius * (u - d.normal * u.dot(d.normal)).length()),
            // x = M y + c over |y| = 1: c.u +- |M^T u|.
            Shape::Ellipsoid(e) => (
                Vec3::from(e.to_world().translation).dot(u),
                (e.to_world().matrix3.transpose() * glam::Vec3A::from(u)).length(),
            ),
            Shape::Cylinder(c) => return c.extent_along(u),
            Shape::Ellipse(e) => return e.extent_along(u),
            Shape::SdfGrid(g) => return g.extent_along(u),
        };
        (c - half, c + half)
    }

    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match self {
            Shape::Triangle(t) => (t.v0.min(t.v1).min(t.v2), t.v0.max(t.v1).max(t.v2)),
            Shape::Sphere(s) => (s.center - Vec3::splat(s.radius), s.center + Vec3::splat(s.radius)),
            Shape::Disk(d) => {
                // Extent of a disk along axis i is r * sqrt(1 - n_i^2).
                let e = d.radius * (Vec3::ONE - d.normal * d.normal).max(Vec3::ZERO).sqrt();
                (d.center - e, d.center + e)
            }
            Shape::Ellipsoid(e) => e.bounds(),
            Shape::Cylinder(c) => c.bounds(),
            Shape::Ellipse(e) => e.bounds(),
            Shape::SdfGrid(g) => g.bounds(),
        }
    }

    /// The shape with every length multiplied by `s` (> 0) about the origin.
    pub fn scaled(&self, s: f32) -> Shape {
        match self {
            Shape::Triangle(t) => {
                Shape::Triangle(Triangle { shading: t.shading, ..Triangle::new(t.v0 * s, t.v1 * s, t.v2 * s) })
            }
            Shape::Sphere(sp) => Shape::Sphere(Sphere { center: sp.center * s, radius: sp.radius * s }),
            Shape::Disk(d) => Shape::Disk(Disk { center: d.center * s, radius: d.radius * s, ..*d }),
            Shape::Ellipsoid(e) => Shape::Ellipsoid(e.scaled(s)),
            Shape::Cylinder(c) => {
                Shape::Cylinder(Cylinder { p0: c.p0 * s, length: c.length * s, radius: c.radius * s, ..*c })
            }
            Shape::Ellipse(e) => Shape::Ellipse(e.scaled(s)),
            Shape::SdfGrid(g) => Shape::SdfGrid(Arc::new(g.scaled(s))),
        }
    }

    /// What the shape is called in messages (an export's refusal).
    pub fn name(&self) -> &'static str {
        match self {
            Shape::Triangle(_) => "triangle",
            Shape::Sphere(_) => "sphere",
            Shape::Disk(_) => "disk",
            Shape::Ellipsoid(_) => "ellipsoid",
            Shape::Cylinder(_) => "cylinder",
            Shape::Ellipse(_) => "ellipse",
            Shape::SdfGrid(_) => "signed-distance grid",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every primitive is as large as the largest shape: a triangle of a
    /// million-triangle mesh pays for the ellipsoid's transform.
    #[test]
    fn a_shape_stays_small() {
        assert!(std::mem::size_of::<Shape>() <= 56, "{} bytes", std::mem::size_of::<Shape>());
    }
}
