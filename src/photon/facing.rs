//! A photon map's (and the irradiance cache's) kd-trees, one per facing
//! class: photons are split by the dominant axis and sign of their surface
//! normal, and a search for photons facing like a normal reads only the
//! classes that can hold one.
//!
//! An estimate counts only photons on a surface facing like its own
//! ([`super::map::PhotonMap`]). Where another surface's photons crowd the
//! disk (the front face of a table under the caustic on its top, a room's
//! wall behind the sunlit floor), one tree over all photons read every one
//! of them to keep none: a hall scene's camera pass spent 70% of its time
//! there. Those classes are asked instead for their nearest photon, which
//! is all an estimate needs of them (whether another surface lies inside
//! its disk).

use super::kdtree::PointTree;
use super::Photon;
use glam::Vec3;
use rayon::prelude::*;

/// A photon of class (axis a, sign s) faces like a unit normal n (cosine
/// at least 0.9, [`super::map::NORMAL_COSINE`]) only if
/// s n_a - |n_j| >= -0.7 for both other axes j: the two unit vectors are
/// then within 0.45 of each other (0.47 with the normals' rounding to
/// bytes), and s m_a - |m_j| >= 0 moves by at most sqrt(2) times that.
const CLASS_MARGIN: f32 = 0.7;

/// Six kd-trees: photons whose normal's largest component is +x, -x, +y,
/// -y, +z, -z.
pub(crate) struct FacingTrees {
    classes: Vec<Class>,
}

struct Class {
    axis: usize,
    sign: f32,
    tree: PointTree,
    /// The photon each tree item is: its place in the order given to
    /// [`FacingTrees::build`].
    items: Vec<u32>,
}

/// The facing class of a normal: 2 * axis + (1 if negative).
pub(super) fn class_of(m: Vec3) -> usize {
    let a = m.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    2 * axis + (m[axis] < 0.0) as usize
}

impl Class {
    /// Class `c` (see [`class_of`]) of `items`, with their tree.
    fn new(c: usize, items: Vec<u32>, tree: PointTree) -> Self {
        let sign = if c.is_multiple_of(2) { 1.0 } else { -1.0 };
        Class { axis: c / 2, sign, tree, items }
    }

    /// Squared distance of the nearest photon within sqrt(r2) of x
    /// (infinite if none): a search bounded by the radius ends soon where
    /// the class has no photon near.
    fn nearest_within(&self, x: Vec3, r2: f32) -> f32 {
        match self.tree.visit_nearest(x, r2, 1, |_| ()) {
            (0, _) => f32::INFINITY,
            (_, d2) => d2,
        }
    }

    /// Whether a photon of this class may face like `n` (never false
    /// where one does).
    fn may_face(&self, n: Vec3) -> bool {
        let lead = self.sign * n[self.axis];
        (0..3).filter(|&j| j != self.axis).all(|j| lead - n[j].abs() >= -CLASS_MARGIN)
    }
}

impl FacingTrees {
    /// Trees over `photons`, in the order given (items are places in it).
    pub(crate) fn build(photons: &[Photon]) -> Self {
        Self::build_from(photons.len(), |i| (photons[i].position(), photons[i].surface_normal()))
    }

    /// Trees over `count` points, point i at `point(i)` = (position,
    /// surface normal); items are the indices i.
    pub(crate) fn build_from(count: usize, point: impl Fn(usize) -> (Vec3, Vec3) + Sync) -> Self {
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); 6];
        for i in 0..count {
            members[class_of(point(i).1)].push(i as u32);
        }
        let classes = members
            .into_par_iter()
            .enumerate()
            .filter(|(_, items)| !items.is_empty())
            .map(|(c, items)| {
                let tree = PointTree::build(items.par_iter().map(|&i| point(i as usize).0));
                Class::new(c, items, tree)
            })
            .collect();
        FacingTrees { classes }
    }

    /// The classes, each as its list of items (the order of the indices
    /// the other methods take).
    pub(crate) fn class_items(&self) -> impl Iterator<Item = &[u32]> {
        self.classes.iter().map(|c| c.items.as_slice())
    }

    /// The indices of the classes that may hold a point facing like `n`.
    pub(crate) fn facing(&self, n: Vec3) -> impl Iterator<Item = usize> + '_ {
        self.classes.iter().enumerate().filter(move |(_, c)| c.may_face(n)).map(|(i, _)| i)
    }

    /// Calls `f` with every point of class `c` within sqrt(r2) of x.
    pub(crate) fn visit_in(&self, c: usize, x: Vec3, r2: f32, mut f: impl FnMut(u32)) {
        let class = &self.classes[c];
        class.tree.visit(x, r2, |item| f(class.items[item as usize]));
    }

    /// Calls `f` with every photon within sqrt(r2) of x in a class that may
    /// face like `n`; returns the squared distance of the nearest photon
    /// of the other classes within that radius (infinite if none).
    pub(crate) fn visit(&self, x: Vec3, r2: f32, n: Vec3, mut f: impl FnMut(u32)) -> f32 {
        let mut other = f32::INFINITY;
        for class in &self.classes {
            if class.may_face(n) {
                class.tree.visit(x, r2, |item| f(class.items[item as usize]));
            } else {
                other = other.min(class.nearest_within(x, r2));
            }
        }
        other
    }

    /// [`Self::visit`] keeping, in each class, only the `count` photons
    /// nearest to x. Returns the nearest photon of the other classes as
    /// `visit` does, and the squared radius within which every photon was
    /// visited (`r2` where no class stopped at `count`).
    pub(crate) fn visit_nearest(&self, x: Vec3, r2: f32, n: Vec3, count: usize, mut f: impl FnMut(u32)) -> (f32, f32) {
        let (mut other, mut complete) = (f32::INFINITY, r2);
        for class in &self.classes {
            if class.may_face(n) {
                let (found, farthest) = class.tree.visit_nearest(x, r2, count, |item| f(class.items[item as usize]));
                if found == count {
                    complete = complete.min(farthest);
                }
            } else {
                other = other.min(class.nearest_within(x, r2));
            }
        }
        (other, complete)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photon::map::NORMAL_COSINE;
    use crate::sampling::{next_2d, stream, Domain};

    /// The class test never rules out a class holding a photon that
    /// faces like the query: random unit normals against the byte-rounded
    /// normals of random photons, and the classes' edges (normals along the
    /// diagonals between axes).
    #[test]
    fn a_class_ruled_out_holds_no_photon_facing_like_the_query() {
        let mut rng = stream(11, Domain::Camera, 0);
        let unit = |u: glam::Vec2| {
            let z = 1.0 - 2.0 * u[0];
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * u[1];
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        };
        let mut checked = 0;
        for i in 0..400_000 {
            let n = unit(next_2d(&mut rng));
            // Photon normals near the query, where the test is tight.
            let jitter = unit(next_2d(&mut rng)) * if i % 2 == 0 { 0.45 } else { 2.0 };
            let m = Photon::new(Vec3::ZERO, Vec3::ONE, (n + jitter).normalize_or(Vec3::Z)).surface_normal();
            if m.dot(n) < NORMAL_COSINE {
                continue;
            }
            checked += 1;
            let c = class_of(m);
            let class = Class::new(c, Vec::new(), PointTree::build(Vec::<Vec3>::new().into_par_iter()));
            assert!(class.may_face(n), "photon normal {m:?} faces {n:?} but class {c} was ruled out");
        }
        assert!(checked > 100_000, "{checked}");
        // Normals in the plane between two axes, facing each other at
        // exactly the cosine bound.
        let half = (NORMAL_COSINE.acos() * 0.999) / 2.0;
        for k in 0..3 {
            let (a, b) = (Vec3::AXES[k], Vec3::AXES[(k + 1) % 3]);
            for t in 0..=100 {
                let mid = std::f32::consts::FRAC_PI_2 * t as f32 / 100.0;
                let n = a * (mid - half).cos() + b * (mid - half).sin();
                let m = Photon::new(Vec3::ZERO, Vec3::ONE, a * (mid + half).cos() + b * (mid + half).sin());
                let c = class_of(m.surface_normal());
                let class = Class::new(c, Vec::new(), PointTree::build(Vec::<Vec3>::new().into_par_iter()));
                assert!(class.may_face(n), "{t}");
            }
        }
    }

    /// An axis-aligned query rules out the four classes across from it.
    #[test]
    fn an_axis_normal_reads_one_class() {
        let photons: Vec<Photon> =
            Vec3::AXES.iter().flat_map(|&a| [a, -a]).map(|m| Photon::new(Vec3::ZERO, Vec3::ONE, m)).collect();
        let trees = FacingTrees::build(&photons);
        assert_eq!(trees.classes.len(), 6);
        for (i, p) in photons.iter().enumerate() {
            let mut seen = Vec::new();
            let other = trees.visit(Vec3::ZERO, 1.0, p.surface_normal(), |item| seen.push(item));
            assert_eq!(seen, vec![i as u32]);
            assert_eq!(other, 0.0);
        }
    }
}
