//! A bounding volume hierarchy over boxes: built binary with the binned
//! surface area heuristic (16 bins), then folded into 4-wide nodes whose
//! four boxes a ray tests at once in SIMD lanes, nearer boxes first, the
//! current closest distance pruning the farther ones.
//!
//! Kept hand-written rather than taken from a crate: the traversal's
//! visitor shrinks the ray's reach as hits are found and stops on the first
//! blocker for shadow rays, and it reports leaf ranges so that the
//! primitives stay in one array in leaf order (notes/architecture.md).

use crate::math::Ray;
use glam::{Vec3, Vec3A, Vec4};

const BINS: usize = 16;
const MAX_LEAF: usize = 4;
/// A step into a node, in units of a primitive's test (the surface area
/// heuristic's traversal cost).
const TRAVERSAL_COST: f32 = 1.0;

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
    /// Primitives of a leaf child (at most MAX_LEAF); 0 for an interior child.
    count: [u8; 4],
    /// Bit k set where lane k holds a child.
    used: u8,
}

/// Entries the traversal stack holds. A node pushes at most three more
/// than it pops, so 128 hold a path 42 nodes deep (a binary tree of ~84
/// levels; the binary traversal's stack held 64); a full stack would drop
/// far boxes rather than overrun.
const STACK: usize = 128;

/// A hierarchy over boxes, walked by [`Bvh::traverse`].
pub struct Bvh {
    nodes: Vec<Node4>,
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

impl Bvh {
    /// The hierarchy over `boxes` (min, max), and the order in which its
    /// leaves hold them: leaf ranges index that order.
    pub fn build(boxes: &[(Vec3, Vec3)]) -> (Bvh, Vec<u32>) {
        let mut items: Vec<Item> = boxes
            .iter()
            .enumerate()
            .map(|(i, &(min, max))| Item { min, max, centroid: 0.5 * (min + max), index: i as u32 })
            .collect();
        let mut nodes = Vec::new();
        if !items.is_empty() {
            let binary = subtree(&mut items, 0);
            nodes.reserve(binary.len() / 3 + 1);
            collapse(&binary, &mut nodes, 0);
        }
        (Bvh { nodes }, items.iter().map(|it| it.index).collect())
    }

    /// Nodes of the 4-wide hierarchy.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Bytes held by the nodes.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node4>()
    }

    /// Visits the leaves whose boxes the ray enters before `t_limit`, nearer
    /// boxes first; `visit` may shrink `t_limit`, and returns true to stop.
    #[inline(always)]
    pub fn traverse(&self, ray: &Ray, t_max: f32, mut visit: impl FnMut(std::ops::Range<usize>, &mut f32) -> bool) {
        if self.nodes.is_empty() {
            return;
        }
        let mut t_limit = t_max;
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
            let mut hits = (t_in.cmple(t_out) & t_in.cmple(Vec4::splat(t_limit)) & t_in.cmplt(Vec4::INFINITY))
                .bitmask()
                & n.used as u32;
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
                    if visit(first..first + count as usize, &mut t_limit) {
                        return;
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
    let mut count = [0u8; 4];
    for (lane, &k) in kids.iter().enumerate() {
        let b = &binary[k];
        for a in 0..3 {
            min[a][lane] = b.min[a];
            max[a][lane] = b.max[a];
        }
        (child[lane], count[lane]) = if b.count > 0 { (b.first, b.count as u8) } else { (collapse(binary, out, k), 0) };
    }
    out[index] = Node4 {
        min: min.map(Vec4::from_array),
        max: max.map(Vec4::from_array),
        child,
        count,
        used: (1u8 << kids.len()) - 1,
    };
    index as u32
}

/// The smallest box holding the items' boxes.
fn item_bounds(items: &[Item]) -> (Vec3, Vec3) {
    items
        .iter()
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(a, b), it| (a.min(it.min), b.max(it.max)))
}

/// How a node of `items` (bounds `min`, `max`) is split: the items
/// partitioned and the size of the first part, or `None` for a leaf. The
/// binned surface area heuristic along the widest axis of the centroids,
/// a step into a node costing as much as a primitive's test (so two to
/// four primitives make a leaf rather than a chain of nodes of one each);
/// halves by count where the centroids coincide.
fn split(items: &mut [Item], min: Vec3, max: Vec3) -> Option<usize> {
    if items.len() <= 1 {
        return None;
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
    if !(extent[axis] > 0.0) {
        return (items.len() > MAX_LEAF).then_some(items.len() / 2);
    }
    let bin_of = |it: &Item| (((it.centroid[axis] - cmin[axis]) / extent[axis] * BINS as f32) as usize).min(BINS - 1);
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
    let node_area = area(min, max);
    let leaf_cost = items.len() as f32 * node_area;
    if best.1 == 0 || (best.0 + TRAVERSAL_COST * node_area >= leaf_cost && items.len() <= MAX_LEAF) {
        return (items.len() > MAX_LEAF).then_some(items.len() / 2);
    }
    let mut i = 0;
    for j in 0..items.len() {
        if bin_of(&items[j]) < best.1 {
            items.swap(i, j);
            i += 1;
        }
    }
    Some(i)
}

/// Builds the binary hierarchy over `items` into `nodes[node]` and nodes
/// pushed after it (an interior node's children adjacent); leaves index
/// the items' order from `offset`.
fn build(nodes: &mut Vec<Node>, node: usize, items: &mut [Item], offset: u32) {
    let (min, max) = item_bounds(items);
    let Some(mid) = split(items, min, max) else {
        nodes[node] = Node { min, max, first: offset, count: items.len() as u32 };
        return;
    };
    let first = nodes.len();
    let placeholder = Node { min, max, first: 0, count: 0 };
    nodes.push(placeholder);
    nodes.push(placeholder);
    nodes[node] = Node { min, max, first: first as u32, count: 0 };
    let (left, right) = items.split_at_mut(mid);
    build(nodes, first, left, offset);
    build(nodes, first + 1, right, offset + mid as u32);
}

/// Items below which a subtree is built on one thread.
const PARALLEL_MIN: usize = 1 << 14;

/// The binary hierarchy over `items` as its own array, root first: the
/// top levels' two halves built at once on the thread pool, each subtree
/// below `PARALLEL_MIN` items by [`build`], then stitched (the same tree as
/// one thread builds, node for node).
fn subtree(items: &mut [Item], offset: u32) -> Vec<Node> {
    let (min, max) = item_bounds(items);
    if items.len() < PARALLEL_MIN {
        let mut nodes = Vec::with_capacity(2 * items.len().max(1));
        nodes.push(Node { min, max, first: 0, count: 0 });
        build(&mut nodes, 0, items, offset);
        return nodes;
    }
    let Some(mid) = split(items, min, max) else {
        return vec![Node { min, max, first: offset, count: items.len() as u32 }];
    };
    let (l, r) = items.split_at_mut(mid);
    let (left, right) = rayon::join(|| subtree(l, offset), || subtree(r, offset + mid as u32));
    // Root, the two subtrees' roots, then the rest of each: old index i of
    // the left tree (i >= 1) becomes i + 2, of the right i + left.len() + 1.
    let moved = |n: &Node, by: u32| if n.count == 0 { Node { first: n.first + by, ..*n } } else { *n };
    let (by_left, by_right) = (2, left.len() as u32 + 1);
    let mut out = Vec::with_capacity(1 + left.len() + right.len());
    out.push(Node { min, max, first: 1, count: 0 });
    out.push(moved(&left[0], by_left));
    out.push(moved(&right[0], by_right));
    out.extend(left[1..].iter().map(|n| moved(n, by_left)));
    out.extend(right[1..].iter().map(|n| moved(n, by_right)));
    out
}
