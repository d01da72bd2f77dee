//! The kd-tree over photon (and cache point) positions: kiddo's immutable
//! tree, the only place the crate is named (a version bump touches this
//! file alone).
//!
//! Positions go into the tree rotated by a fixed generic rotation: photons
//! on axis-aligned walls share one coordinate exactly, which makes kd-tree
//! splits degenerate and queries slow (kiddo's issues #78, #158); distances
//! are unchanged by a rotation.

use glam::{EulerRot, Mat3, Vec3};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use std::num::NonZeroUsize;

fn rotation() -> Mat3 {
    Mat3::from_euler(EulerRot::XYZ, 0.61, 0.93, 0.37)
}

/// A point found at squared distance `d2` (not negative), as one integer
/// whose order is that of (d2, index): the bits of a non-negative float
/// order like the float. Ranking by index among equal distances makes the k
/// nearest one set whatever order the search met them in, and sorting
/// integers is cheaper than comparing pairs.
#[inline]
pub(crate) fn found(d2: f32, index: u32) -> u64 {
    ((d2.max(0.0).to_bits() as u64) << 32) | index as u64
}

/// The squared distance and index of a [`found`] key.
#[inline]
pub(crate) fn unpack(key: u64) -> (f32, u32) {
    (f32::from_bits((key >> 32) as u32), key as u32)
}

/// A kd-tree over points, with the rotation applied on the way in.
pub(crate) struct PointTree {
    tree: Option<ImmutableKdTree<f32, 3>>,
    rot: Mat3,
}

impl PointTree {
    pub(crate) fn build(points: impl IndexedParallelIterator<Item = Vec3>) -> Self {
        let rot = rotation();
        let pts: Vec<[f32; 3]> = points.map(|p| (rot * p).to_array()).collect();
        // An empty map has no tree; queries on it find nothing.
        let tree = if pts.is_empty() { None } else { ImmutableKdTree::new_from_slice(&pts).ok() };
        PointTree { tree, rot }
    }

    /// Calls `f` with the index of every point within sqrt(r2) of x.
    pub(crate) fn visit(&self, x: Vec3, r2: f32, mut f: impl FnMut(u32)) {
        if let Some(tree) = &self.tree {
            tree.query(&(self.rot * x).to_array()).within::<SquaredEuclidean<f32>>(r2).unsorted().visit(|n| f(n.item));
        }
    }

    /// Calls `f` with the index of each of the `n` points nearest to x
    /// within sqrt(r2) (all of them, where fewer lie there), in no set
    /// order; returns how many, and the squared distance of the farthest.
    pub(crate) fn visit_nearest(&self, x: Vec3, r2: f32, n: usize, mut f: impl FnMut(u32)) -> (usize, f32) {
        let (Some(tree), Some(n)) = (&self.tree, NonZeroUsize::new(n)) else {
            return (0, 0.0);
        };
        let found = tree
            .query(&(self.rot * x).to_array())
            .nearest_n::<SquaredEuclidean<f32>>(n)
            .within(r2)
            .unsorted()
            .execute();
        let farthest = found.iter().map(|p| p.distance).fold(0.0, f32::max);
        found.iter().for_each(|p| f(p.item));
        (found.len(), farthest)
    }
}
