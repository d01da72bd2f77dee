//! Closest-hit and occlusion queries over the scene's primitives. Every ray
//! of the renderer goes through here.
//!
//! A closed convex room of triangles is met as a polyhedron
//! ([`enclosure`]); everything else sits in a bounding volume hierarchy
//! built binary with the binned surface area heuristic (16 bins), then
//! folded into 4-wide nodes whose four boxes a ray tests at once, nearer
//! boxes first, the current closest distance pruning the farther ones. The
//! room is tested first: the wall a ray would reach bounds the search among
//! the objects inside.

pub mod enclosure;

use crate::math::Ray;
use crate::shape::{Departure, Shape, ShapeHit};
use enclosure::Enclosure;
use glam::{Vec3, Vec3A, Vec4};

const BINS: usize = 16;
/// Up to this many primitives a flat loop beats the hierarchy. With the
/// room's walls in the enclosure, the tree over the 7 objects inside it
/// takes random rays from 157 to 87 ns (notes/performance.md).
pub const FLAT_LIMIT: usize = 2;
const MAX_LEAF: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Node {
    min: Vec3,
    max: Vec3,
    /// Interior: index of the first of two adjacent children. Leaf: index of
    /// the first primitive in leaf order.
    first: u32,
    /// Primitives in the leaf; 0 for interior nodes.
    count: u32,
}

/// A node of the 4-wide hierarchy the traversal walks: four children's
/// boxes in SIMD lanes, tested at once. It is the binary SAH tree with
/// every other level folded in (nodes with the largest boxes opened
/// first): random rays in the default room visit one node, not the
/// binary tree's chain of two-box tests whose branches they mispredict.
#[derive(Clone, Copy, Debug)]
struct Node4 {
    min: [Vec4; 3],
    max: [Vec4; 3],
    /// Interior child: its node. Leaf child: its first primitive in leaf order.
    child: [u32; 4],
    /// Primitives of a leaf child; 0 for an interior child.
    count: [u32; 4],
    /// Bit k set where lane k holds a child.
    used: u32,
}

/// Entries the traversal stack holds. A node pushes at most three more
/// than it pops, so 128 hold a path 42 nodes deep (a binary tree of ~84
/// levels; the binary traversal's stack held 64); a full stack would drop
/// far boxes rather than overrun.
const STACK: usize = 128;

pub struct Accel {
    /// Empty when the primitives are few enough to test them all.
    nodes: Vec<Node4>,
    /// Shapes in leaf order, with their index in the scene (those of the
    /// enclosure left out).
    shapes: Vec<(Shape, u32)>,
    enclosure: Option<Enclosure>,
}

#[derive(Clone, Copy)]
struct Item {
    min: Vec3,
    max: Vec3,
    centroid: Vec3,
    index: u32,
}

fn area(min: Vec3, max: Vec3) -> f32 {
    let d = (max - min).max(Vec3::ZERO);
    2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
}

impl Accel {
    /// A hierarchy over all the shapes (no enclosure).
    pub fn new(shapes: Vec<Shape>) -> Self {
        Self::build(shapes, None, FLAT_LIMIT)
    }

    /// The accelerator of a scene: the enclosure, if the shapes hold one
    /// ([`Enclosure::detect`]; `group[i]` is primitive i's material, `None`
    /// for a light), and a hierarchy over the rest.
    pub fn with_enclosure(shapes: Vec<Shape>, group: &[Option<u32>]) -> Self {
        let enclosure = Enclosure::detect(&shapes, group);
        Self::build(shapes, enclosure, FLAT_LIMIT)
    }

    /// As [`Accel::new`], choosing the flat loop up to `flat_limit` primitives.
    pub fn with_flat_limit(shapes: Vec<Shape>, flat_limit: usize) -> Self {
        Self::build(shapes, None, flat_limit)
    }

    /// The enclosure found, if any.
    pub fn enclosure(&self) -> Option<&Enclosure> {
        self.enclosure.as_ref()
    }

    fn build(shapes: Vec<Shape>, enclosure: Option<Enclosure>, flat_limit: usize) -> Self {
        let inside = |i: usize| !enclosure.as_ref().is_some_and(|e| e.contains(i as u32));
        let rest: Vec<(Shape, u32)> =
            shapes.iter().enumerate().filter(|&(i, _)| inside(i)).map(|(i, s)| (*s, i as u32)).collect();
        if rest.len() <= flat_limit {
            return Accel { nodes: Vec::new(), shapes: rest, enclosure };
        }
        let mut items: Vec<Item> = rest
            .iter()
            .map(|&(s, i)| {
                let (min, max) = s.bounds();
                Item { min, max, centroid: 0.5 * (min + max), index: i }
            })
            .collect();
        let mut binary = Vec::with_capacity(2 * items.len().max(1));
        binary.push(Node { min: Vec3::ZERO, max: Vec3::ZERO, first: 0, count: 0 });
        let mut nodes = Vec::new();
        if !items.is_empty() {
            build(&mut binary, 0, &mut items, 0);
            collapse(&binary, &mut nodes, 0);
        }
        let ordered = items.iter().map(|it| (shapes[it.index as usize], it.index)).collect();
        Accel { nodes, shapes: ordered, enclosure }
    }

    /// Where the ray meets the enclosure before `t_max` (never the face it
    /// departs from).
    #[inline]
    fn enclosure_hit(&self, ray: &Ray, departure: Option<Departure>, t_max: f32) -> Option<enclosure::EnclosureHit> {
        let e = self.enclosure.as_ref()?;
        let skip = departure.map_or(u32::MAX, |d| e.face_of(d.prim));
        e.hit(ray, skip, t_max)
    }

    /// How far the search among the objects inside reaches: to the wall,
    /// plus its rounding, so that a primitive lying on a face (a rug on the
    /// floor, a light set in the ceiling) wins the tie with it; nothing lies
    /// behind a face.
    fn inside_limit(wall: Option<enclosure::EnclosureHit>, t_max: f32) -> f32 {
        wall.map_or(t_max, |w| (w.t * (1.0 + crate::math::gamma(8))).min(t_max))
    }

    /// Nearest hit in (0, t_max) and the index of the primitive hit.
    pub fn closest_hit(&self, ray: &Ray, departure: Option<Departure>, t_max: f32) -> Option<(u32, ShapeHit)> {
        let wall = self.enclosure_hit(ray, departure, t_max);
        let mut best: Option<(&Shape, u32, f32, [f32; 2])> = None;
        let rs = std::cell::OnceCell::new();
        self.traverse(ray, Self::inside_limit(wall, t_max), |shape, index, t_limit| {
            let departed = departure.filter(|d| d.prim == index).map(|d| d.outward);
            if let Some((t, uv)) = shape.distance(ray, &rs, *t_limit, departed) {
                *t_limit = t;
                best = Some((shape, index, t, uv));
            }
            false
        });
        // Only the nearest hit needs its point and error bound.
        match (best, wall) {
            (Some((shape, index, t, uv)), _) => Some((index, shape.record(ray, t, uv))),
            (None, Some(w)) => self.enclosure.as_ref().map(|e| e.record(ray, w)),
            (None, None) => None,
        }
    }

    /// Primitives a closest-hit query tests (a diagnostic of the tree's quality).
    pub fn count_tests(&self, ray: &Ray) -> u64 {
        let mut n = 0;
        let rs = std::cell::OnceCell::new();
        let wall = self.enclosure_hit(ray, None, f32::INFINITY);
        self.traverse(ray, Self::inside_limit(wall, f32::INFINITY), |shape, _, t_limit| {
            n += 1;
            if let Some((t, _)) = shape.distance(ray, &rs, *t_limit, None) {
                *t_limit = t;
            }
            false
        });
        n
    }

    /// Whether anything other than primitive `ignore` lies in (0, t_max).
    pub fn occluded(&self, ray: &Ray, departure: Option<Departure>, t_max: f32, ignore: Option<u32>) -> bool {
        // `ignore` is a light, never part of the enclosure.
        if self.enclosure_hit(ray, departure, t_max).is_some() {
            return true;
        }
        let mut blocked = false;
        let rs = std::cell::OnceCell::new();
        self.traverse(ray, t_max, |shape, index, t_limit| {
            if ignore == Some(index) {
                return false;
            }
            let departed = departure.filter(|d| d.prim == index).map(|d| d.outward);
            blocked = shape.distance(ray, &rs, *t_limit, departed).is_some();
            blocked
        });
        blocked
    }

    /// Visits the leaves whose boxes the ray enters before `t_limit`, nearer
    /// boxes first; `visit` may shrink `t_limit`, and returns true to stop.
    fn traverse<'s>(&'s self, ray: &Ray, t_max: f32, mut visit: impl FnMut(&'s Shape, u32, &mut f32) -> bool) {
        if self.shapes.is_empty() {
            return;
        }
        let mut t_limit = t_max;
        if self.nodes.is_empty() {
            for (shape, index) in &self.shapes {
                if visit(shape, *index, &mut t_limit) {
                    return;
                }
            }
            return;
        }
        let inv = Vec3A::from(ray.dir).recip();
        let origin = [Vec4::splat(ray.origin.x), Vec4::splat(ray.origin.y), Vec4::splat(ray.origin.z)];
        let inv = [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)];
        // Interior children to open later, (node, entry distance), nearest
        // on top; made on the first push (a tree of one node never needs it,
        // and zeroing it per ray cost more than the default room's rays).
        let mut stack: Option<[(u32, f32); STACK]> = None;
        let mut top = 0usize;
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            let (t_in, t_out) = entries(n, origin, inv);
            let mut hits =
                (t_in.cmple(t_out) & t_in.cmple(Vec4::splat(t_limit)) & t_in.cmplt(Vec4::INFINITY)).bitmask() & n.used;
            let t_in = t_in.to_array();
            // The boxes entered, nearest first (on a tie, the lower lane).
            let mut order = [0usize; 4];
            let mut entered = 0;
            while hits != 0 {
                let k = hits.trailing_zeros() as usize;
                hits &= hits - 1;
                let mut j = entered;
                while j > 0 && t_in[order[j - 1]] > t_in[k] {
                    order[j] = order[j - 1];
                    j -= 1;
                }
                order[j] = k;
                entered += 1;
            }
            // Leaves now, nearest first: their hits prune what follows.
            for &k in &order[..entered] {
                let count = n.count[k];
                if count > 0 && t_in[k] <= t_limit {
                    let first = n.child[k] as usize;
                    for (shape, index) in &self.shapes[first..first + count as usize] {
                        if visit(shape, *index, &mut t_limit) {
                            return;
                        }
                    }
                }
            }
            // Interior children onto the stack, farthest first.
            for &k in order[..entered].iter().rev() {
                if n.count[k] == 0 && top < STACK {
                    stack.get_or_insert([(0, 0.0); STACK])[top] = (n.child[k], t_in[k]);
                    top += 1;
                }
            }
            // Pop, skipping boxes that the shrinking closest hit now excludes.
            loop {
                let Some(stack) = stack.as_ref().filter(|_| top > 0) else { return };
                top -= 1;
                let (child, t) = stack[top];
                if t <= t_limit {
                    node = child;
                    break;
                }
            }
        }
    }
}

/// Distances at which the ray enters and leaves each of the node's four
/// boxes (0 for a box it starts in); a box is missed where the entry
/// comes after the exit. A lane is NaN only from 0 * inf (a ray parallel to
/// a slab, starting on its plane): such a slab constrains nothing, so a box
/// is never dropped for it (at worst a box the ray only grazes is visited).
#[inline(always)]
fn entries(n: &Node4, origin: [Vec4; 3], inv: [Vec4; 3]) -> (Vec4, Vec4) {
    let mut t_in = Vec4::ZERO;
    let mut t_out = Vec4::INFINITY;
    for a in 0..3 {
        let t0 = (n.min[a] - origin[a]) * inv[a];
        let t1 = (n.max[a] - origin[a]) * inv[a];
        let (near, far) = (t0.min(t1), t0.max(t1));
        t_in = t_in.max(Vec4::select(near.is_nan_mask(), Vec4::NEG_INFINITY, near));
        t_out = t_out.min(Vec4::select(far.is_nan_mask(), Vec4::INFINITY, far));
    }
    // Widen the exit by a few ulps so rounding never drops a box a ray grazes.
    (t_in, t_out * (1.0 + 2.0 * crate::math::gamma(3)))
}

/// Folds the binary tree under `root` into 4-wide nodes appended to `out`;
/// returns the index of the node made for `root`. Of the binary nodes below
/// a 4-wide node, the interior one with the largest box is opened first,
/// until there are four children or only leaves.
fn collapse(binary: &[Node], out: &mut Vec<Node4>, root: usize) -> u32 {
    let mut kids = vec![root];
    while kids.len() < 4 {
        let open = kids
            .iter()
            .enumerate()
            .filter(|&(_, &k)| binary[k].count == 0)
            .max_by(|a, b| {
                area(binary[*a.1].min, binary[*a.1].max).total_cmp(&area(binary[*b.1].min, binary[*b.1].max))
            })
            .map(|(i, _)| i);
        let Some(i) = open else { break };
        let first = binary[kids[i]].first as usize;
        kids.splice(i..=i, [first, first + 1]);
    }
    let index = out.len();
    out.push(Node4 { min: [Vec4::ZERO; 3], max: [Vec4::ZERO; 3], child: [0; 4], count: [0; 4], used: 0 });
    let mut min = [[0.0f32; 4]; 3];
    let mut max = [[0.0f32; 4]; 3];
    let mut child = [0u32; 4];
    let mut count = [0u32; 4];
    for (lane, &k) in kids.iter().enumerate() {
        let b = &binary[k];
        for a in 0..3 {
            min[a][lane] = b.min[a];
            max[a][lane] = b.max[a];
        }
        (child[lane], count[lane]) = if b.count > 0 { (b.first, b.count) } else { (collapse(binary, out, k), 0) };
    }
    out[index] = Node4 {
        min: min.map(Vec4::from_array),
        max: max.map(Vec4::from_array),
        child,
        count,
        used: (1u32 << kids.len()) - 1,
    };
    index as u32
}

fn build(nodes: &mut Vec<Node>, node: usize, items: &mut [Item], offset: u32) {
    let (min, max) = items.iter().fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(a, b), it| {
        (a.min(it.min), b.max(it.max))
    });
    let leaf = Node { min, max, first: offset, count: items.len() as u32 };
    if items.len() <= 1 {
        nodes[node] = leaf;
        return;
    }
    let (cmin, cmax) = items.iter().fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(a, b), it| {
        (a.min(it.centroid), b.max(it.centroid))
    });
    let extent = cmax - cmin;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = if extent[axis] > 0.0 {
        // Binned SAH along the widest centroid axis.
        let bin_of =
            |it: &Item| (((it.centroid[axis] - cmin[axis]) / extent[axis] * BINS as f32) as usize).min(BINS - 1);
        let mut counts = [0usize; BINS];
        let mut bounds = [(Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)); BINS];
        for it in items.iter() {
            let b = bin_of(it);
            counts[b] += 1;
            bounds[b] = (bounds[b].0.min(it.min), bounds[b].1.max(it.max));
        }
        let mut best = (f32::INFINITY, 0usize);
        for split in 1..BINS {
            let side = |range: std::ops::Range<usize>| {
                range.fold((0usize, Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(c, a, b), i| {
                    (c + counts[i], a.min(bounds[i].0), b.max(bounds[i].1))
                })
            };
            let (nl, al, bl) = side(0..split);
            let (nr, ar, br) = side(split..BINS);
            if nl == 0 || nr == 0 {
                continue;
            }
            let cost = nl as f32 * area(al, bl) + nr as f32 * area(ar, br);
            if cost < best.0 {
                best = (cost, split);
            }
        }
        let leaf_cost = items.len() as f32 * area(min, max);
        if best.1 == 0 || (best.0 >= leaf_cost && items.len() <= MAX_LEAF) {
            if items.len() <= MAX_LEAF {
                nodes[node] = leaf;
                return;
            }
            items.len() / 2
        } else {
            let mut i = 0;
            for j in 0..items.len() {
                if bin_of(&items[j]) < best.1 {
                    items.swap(i, j);
                    i += 1;
                }
            }
            i
        }
    } else if items.len() <= MAX_LEAF {
        nodes[node] = leaf;
        return;
    } else {
        items.len() / 2
    };
    let first = nodes.len();
    nodes.push(leaf);
    nodes.push(leaf);
    nodes[node] = Node { min, max, first: first as u32, count: 0 };
    let (left, right) = items.split_at_mut(mid);
    build(nodes, first, left, offset);
    build(nodes, first + 1, right, offset + mid as u32);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, uniform_cone, Domain};
    use crate::shape::{Sphere, Triangle};

    /// Regression: while no hit bounded the ray, a box the ray misses
    /// (entry distance infinity) passed the test `t <= t_limit` with
    /// t_limit = infinity, so a ray missing a 100k-triangle torus tested
    /// every triangle (91,080 tests per random ray; 330 us per camera ray).
    #[test]
    fn a_ray_that_misses_every_box_tests_no_primitive() {
        let torus = crate::scene::mesh::torus(glam::Vec3::ZERO, 2.0, 0.5, 100, 50);
        let shapes: Vec<Shape> = torus.iter().map(|[a, b, c]| Shape::Triangle(Triangle::new(*a, *b, *c))).collect();
        let accel = Accel::new(shapes);
        let miss = Ray::new(glam::Vec3::new(0.0, 0.0, 5.0), glam::Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(accel.count_tests(&miss), 0);
        // A ray through the tube tests a handful, not thousands.
        let through = Ray::new(glam::Vec3::new(-5.0, 0.01, 0.013), glam::Vec3::X);
        let n = accel.count_tests(&through);
        assert!(n > 0 && n < 100, "{n} tests");
    }

    /// With the room's walls met as a polyhedron, every ray must find what
    /// it finds among the triangles: the same primitive (or one tiling the
    /// same face) at the same distance, from inside and outside the room,
    /// and the same occlusion. Rays aimed at the room's edges and corners
    /// (where triangles meet) are included.
    #[test]
    fn the_enclosure_finds_what_the_triangles_find() {
        use crate::scene::{Eye, Scene};
        let parts = Scene::tncg15_parts(Eye::One);
        let shapes: Vec<Shape> = parts.prims.iter().map(|p| p.shape).collect();
        let group: Vec<Option<u32>> = parts.prims.iter().map(|p| Some(p.material)).collect();
        let plain = Accel::new(shapes.clone());
        let fast = Accel::with_enclosure(shapes.clone(), &group);
        let e = fast.enclosure().expect("the room is an enclosure");
        let mut rng = stream(11, Domain::Camera, 0);
        let corners: Vec<glam::Vec3> = shapes[..24]
            .iter()
            .flat_map(|s| if let Shape::Triangle(t) = s { vec![t.v0, t.v1, t.v2] } else { vec![] })
            .collect();
        let (mut checked, mut outside) = (0, 0);
        for i in 0..200_000 {
            let u = |rng: &mut _| next_2d(rng);
            // Origins in a box larger than the room (some outside it).
            let o = glam::Vec3::new(-5.0, -8.0, -7.0)
                + glam::Vec3::new(20.0, 16.0, 14.0) * {
                    let (a, b) = (u(&mut rng), u(&mut rng));
                    glam::Vec3::new(a.x, a.y, b.x)
                };
            let dir = if i % 4 == 0 {
                // At an edge: a point between two of the room's vertices.
                let a = corners[(u(&mut rng).x * corners.len() as f32) as usize % corners.len()];
                let b = corners[(u(&mut rng).x * corners.len() as f32) as usize % corners.len()];
                (a.lerp(b, u(&mut rng).x) - o).normalize()
            } else {
                uniform_cone(u(&mut rng), -1.0)
            };
            let ray = Ray::new(o, dir);
            if !dir.is_finite() {
                continue;
            }
            let want = plain.closest_hit(&ray, None, f32::INFINITY);
            let got = fast.closest_hit(&ray, None, f32::INFINITY);
            match (want, got) {
                (Some((a, ha)), Some((b, hb))) => {
                    // Or, at an edge, the face on its other side, or a
                    // triangle lying on the face (the tetrahedron's base on
                    // the floor, met from below): the point then lies on
                    // both planes.
                    let same_face = a == b || (e.contains(a) && e.face_of(a) == e.face_of(b));
                    let on_plane = |prim: u32, p: glam::Vec3| matches!(shapes[prim as usize], Shape::Triangle(t) if t.normal.dot(p - t.v0).abs() < 1e-3);
                    let on_edge = (e.contains(a) || e.contains(b)) && on_plane(a, hb.point) && on_plane(b, ha.point);
                    assert!(same_face || on_edge, "ray {ray:?}: prim {a} at {} vs {b} at {}", ha.t, hb.t);
                    // A grazing ray's distance is ill-conditioned (its error
                    // grows as 1 / cos): compare where it is not.
                    if hb.normal.dot(dir).abs() > 0.01 {
                        assert!((ha.t - hb.t).abs() <= 1e-4 * ha.t.max(1.0), "ray {ray:?}: t {} vs {}", ha.t, hb.t);
                        assert!((ha.point - hb.point).abs().max_element() <= 1e-3);
                    }
                }
                // A ray from outside that only touches an edge or a corner
                // (a chord of zero length) may slip between two triangles,
                // but not between two planes: the polyhedron may find a hit
                // the triangles miss there, and only there.
                (None, Some((b, hb))) => {
                    assert!(e.contains(b), "ray {ray:?}: extra hit on {b}");
                    let mut planes: Vec<glam::Vec3> = Vec::new();
                    for s in &shapes[..24] {
                        if let Shape::Triangle(t) = s {
                            let near = t.normal.dot(hb.point - t.v0).abs() < 1e-3;
                            if near && !planes.iter().any(|n| n.dot(t.normal).abs() > 0.99) {
                                planes.push(t.normal);
                            }
                        }
                    }
                    assert!(planes.len() >= 2, "ray {ray:?}: extra hit at {} on one face only", hb.point);
                    outside += 1;
                    continue;
                }
                (Some((a, _)), None) => panic!("ray {ray:?}: the enclosure missed prim {a}"),
                (None, None) => {}
            }
            let t = want.map_or(10.0, |w| w.1.t);
            for t_max in [0.5 * t, 2.0 * t] {
                if (t_max - t).abs() > 1e-3 {
                    assert_eq!(
                        fast.occluded(&ray, None, t_max, None),
                        plain.occluded(&ray, None, t_max, None),
                        "{ray:?}"
                    );
                }
            }
            checked += 1;
        }
        assert!(checked > 190_000);
        assert!(outside < 2_000, "{outside} rays hit only the polyhedron");
    }

    /// A triangle lying on a face of the enclosure (a rug on the floor)
    /// is what rays see there, not the face under it.
    #[test]
    fn a_rug_on_the_floor_wins_over_the_floor() {
        use crate::scene::{Eye, Scene};
        let parts = Scene::tncg15_parts(Eye::One);
        let mut shapes: Vec<Shape> = parts.prims.iter().map(|p| p.shape).collect();
        let mut group: Vec<Option<u32>> = parts.prims.iter().map(|p| Some(p.material)).collect();
        let z = -5.0;
        for (a, b, c) in [((2.0, -2.0), (6.0, -2.0), (6.0, 2.0)), ((2.0, -2.0), (6.0, 2.0), (2.0, 2.0))] {
            let v = |(x, y): (f32, f32)| glam::Vec3::new(x, y, z);
            shapes.push(Shape::Triangle(Triangle::new(v(a), v(b), v(c))));
            group.push(Some(99));
        }
        let rug = [shapes.len() as u32 - 2, shapes.len() as u32 - 1];
        let accel = Accel::with_enclosure(shapes, &group);
        assert_eq!(accel.enclosure().map(|e| e.faces()), Some(8), "the rug does not break the room");
        let mut rng = stream(4, Domain::Camera, 0);
        for _ in 0..20_000 {
            let u = next_2d(&mut rng);
            let target = glam::Vec3::new(2.05 + 3.9 * u.x, -1.95 + 3.9 * u.y, z);
            let w = next_2d(&mut rng);
            let origin = glam::Vec3::new(-1.0 + 10.0 * w.x, -4.0 + 8.0 * w.y, 4.0);
            let ray = Ray::new(origin, (target - origin).normalize());
            let hit = accel.closest_hit(&ray, None, f32::INFINITY).map(|h| h.0);
            assert!(hit.is_some_and(|p| rug.contains(&p)), "{ray:?} -> {hit:?}");
        }
    }

    /// A deep tree (a 10,000-triangle torus: 4-wide nodes several levels
    /// deep, the traversal stack in use) finds what the flat loop finds:
    /// the same rays hit, at the same distance, and the same are occluded.
    #[test]
    fn a_deep_hierarchy_agrees_with_the_flat_loop() {
        let torus = crate::scene::mesh::torus(glam::Vec3::ZERO, 2.0, 0.5, 100, 50);
        let shapes: Vec<Shape> = torus.iter().map(|[a, b, c]| Shape::Triangle(Triangle::new(*a, *b, *c))).collect();
        let tree = Accel::new(shapes.clone());
        assert!(tree.nodes.len() > 100, "{} nodes", tree.nodes.len());
        let flat = Accel::with_flat_limit(shapes, usize::MAX);
        let mut rng = stream(23, Domain::Camera, 0);
        let mut hits = 0;
        for i in 0..3000 {
            let o = (glam::Vec3::new(next_2d(&mut rng).x, next_2d(&mut rng).x, next_2d(&mut rng).x) - 0.5) * 8.0;
            // Half the rays aimed at the ring, so that most of them hit.
            let dir = if i % 2 == 0 {
                let a = next_2d(&mut rng).x * std::f32::consts::TAU;
                (glam::Vec3::new(2.0 * a.cos(), 2.0 * a.sin(), 0.0) - o).normalize()
            } else {
                uniform_cone(next_2d(&mut rng), -1.0)
            };
            let ray = Ray::new(o, dir);
            let (a, b) = (tree.closest_hit(&ray, None, f32::INFINITY), flat.closest_hit(&ray, None, f32::INFINITY));
            assert_eq!(a.is_some(), b.is_some(), "{ray:?}");
            if let (Some((_, ha)), Some((_, hb))) = (a, b) {
                assert!((ha.t - hb.t).abs() <= 1e-5 * ha.t, "{ray:?}: {} vs {}", ha.t, hb.t);
                hits += 1;
                let t = ha.t;
                assert!(tree.occluded(&ray, None, 1.01 * t, None) && !tree.occluded(&ray, None, 0.99 * t, None));
            }
        }
        assert!(hits > 1000, "{hits} hits");
    }

    /// The hierarchy must find exactly what testing every shape finds.
    #[test]
    fn bvh_agrees_with_brute_force() {
        let mut rng = stream(3, Domain::Camera, 0);
        let mut shapes = Vec::new();
        for _ in 0..300 {
            let c = (glam::Vec3::new(next_2d(&mut rng).x, next_2d(&mut rng).x, next_2d(&mut rng).x) - 0.5) * 20.0;
            if shapes.len() % 3 == 0 {
                shapes.push(Shape::Sphere(Sphere { center: c, radius: 0.3 + next_2d(&mut rng).x }));
            } else {
                let d = |rng: &mut _| uniform_cone(next_2d(rng), -1.0) * 1.5;
                shapes.push(Shape::Triangle(Triangle::new(c, c + d(&mut rng), c + d(&mut rng))));
            }
        }
        let accel = Accel::with_flat_limit(shapes.clone(), 0);
        for _ in 0..5000 {
            let o = (glam::Vec3::new(next_2d(&mut rng).x, next_2d(&mut rng).x, next_2d(&mut rng).x) - 0.5) * 30.0;
            let ray = Ray::new(o, uniform_cone(next_2d(&mut rng), -1.0));
            let brute = shapes
                .iter()
                .enumerate()
                .filter_map(|(i, s)| s.intersect(&ray, f32::INFINITY, None).map(|h| (i as u32, h.t)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let got = accel.closest_hit(&ray, None, f32::INFINITY).map(|(i, h)| (i, h.t));
            assert_eq!(got, brute);
            let t = brute.map_or(10.0, |b| b.1 * 1.01);
            assert_eq!(accel.occluded(&ray, None, t, None), brute.is_some_and(|b| b.1 < t));
        }
    }
}
