//! Closest-hit and occlusion queries over the scene's primitives.
//!
//! The default scene has 31 primitives, for which a flat loop over compact
//! shapes is as fast as a hierarchy; every ray of the renderer goes through
//! this one interface, so a BVH for large meshes can replace the loop here
//! without touching any caller.

use crate::math::Ray;
use crate::shape::{Departure, Shape, ShapeHit};

pub struct Accel {
    shapes: Vec<Shape>,
}

impl Accel {
    pub fn new(shapes: Vec<Shape>) -> Self {
        Accel { shapes }
    }

    /// Nearest hit in (0, t_max) and the index of the primitive hit.
    pub fn closest_hit(
        &self,
        ray: &Ray,
        departure: Option<Departure>,
        mut t_max: f32,
    ) -> Option<(u32, ShapeHit)> {
        let mut best = None;
        for (i, shape) in self.shapes.iter().enumerate() {
            let departed = departure
                .filter(|d| d.prim as usize == i)
                .map(|d| d.outward);
            if let Some(h) = shape.intersect(ray, t_max, departed) {
                t_max = h.t;
                best = Some((i as u32, h));
            }
        }
        best
    }

    /// Whether anything other than primitive `ignore` lies in (0, t_max).
    pub fn occluded(
        &self,
        ray: &Ray,
        departure: Option<Departure>,
        t_max: f32,
        ignore: Option<u32>,
    ) -> bool {
        self.shapes.iter().enumerate().any(|(i, shape)| {
            if ignore == Some(i as u32) {
                return false;
            }
            let departed = departure
                .filter(|d| d.prim as usize == i)
                .map(|d| d.outward);
            shape.intersect(ray, t_max, departed).is_some()
        })
    }
}
