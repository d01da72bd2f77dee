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

mod bvh;
pub mod enclosure;

use crate::math::Ray;
use crate::shape::{Departure, Shape, ShapeHit};
use bvh::Bvh;
use enclosure::Enclosure;

/// Up to this many primitives a flat loop beats the hierarchy. With the
/// room's walls in the enclosure, the tree over the 7 objects inside it
/// takes random rays from 157 to 87 ns (notes/performance.md).
pub const FLAT_LIMIT: usize = 2;

/// The scene's shapes, and the structures that find what a ray meets.
pub struct Accel {
    /// Empty when the primitives are few enough to test them all.
    bvh: Bvh,
    /// Every shape with its index in the scene: first those searched (in
    /// the hierarchy's leaf order), then those of the enclosure. The scene
    /// keeps no other copy.
    shapes: Vec<(Shape, u32)>,
    /// How many of `shapes` the hierarchy (or the flat loop) searches.
    searched: usize,
    /// Where each primitive is in `shapes`.
    slot: Vec<u32>,
    enclosure: Option<Enclosure>,
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
        let in_enclosure = |i: usize| enclosure.as_ref().is_some_and(|e| e.contains(i as u32));
        let searched: Vec<u32> = (0..shapes.len()).filter(|&i| !in_enclosure(i)).map(|i| i as u32).collect();
        let (bvh, order) = if searched.len() <= flat_limit {
            (Bvh::build(&[]).0, searched)
        } else {
            let boxes: Vec<_> = searched.iter().map(|&i| shapes[i as usize].bounds()).collect();
            let (bvh, order) = Bvh::build(&boxes);
            (bvh, order.iter().map(|&k| searched[k as usize]).collect())
        };
        let count = order.len();
        let order: Vec<u32> =
            order.into_iter().chain((0..shapes.len() as u32).filter(|&i| in_enclosure(i as usize))).collect();
        let mut slot = vec![0u32; shapes.len()];
        for (k, &i) in order.iter().enumerate() {
            slot[i as usize] = k as u32;
        }
        let shapes = order.iter().map(|&i| (shapes[i as usize].clone(), i)).collect();
        Accel { bvh, shapes, searched: count, slot, enclosure }
    }

    /// The shape of primitive `prim`.
    pub fn shape(&self, prim: u32) -> &Shape {
        &self.shapes[self.slot[prim as usize] as usize].0
    }

    /// Bytes held: the shapes, their slots, the hierarchy's nodes.
    pub fn memory_bytes(&self) -> usize {
        self.shapes.capacity() * std::mem::size_of::<(Shape, u32)>()
            + self.slot.capacity() * 4
            + self.bvh.memory_bytes()
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

    /// Visits the shapes in the leaves whose boxes the ray enters before
    /// `t_max`, nearer boxes first (all of them when there is no
    /// hierarchy); `visit` may shrink the reach, and returns true to stop.
    #[inline(always)]
    fn traverse<'s>(&'s self, ray: &Ray, t_max: f32, mut visit: impl FnMut(&'s Shape, u32, &mut f32) -> bool) {
        if self.bvh.is_empty() {
            let mut t_limit = t_max;
            for (shape, index) in &self.shapes[..self.searched] {
                if visit(shape, *index, &mut t_limit) {
                    return;
                }
            }
            return;
        }
        self.bvh.traverse(ray, t_max, |leaf, t_limit| {
            self.shapes[leaf].iter().any(|(shape, index)| visit(shape, *index, t_limit))
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, uniform_cone, Domain};
    use crate::shape::{Departure, Sphere, Triangle};

    /// Regression: while no hit bounded the ray, a box the ray misses
    /// (entry distance infinity) passed the test `t <= t_limit` with
    /// t_limit = infinity, so a ray missing a 100k-triangle torus tested
    /// every triangle (91,080 tests per random ray; 330 us per camera ray).
    #[test]
    fn a_ray_that_misses_every_box_tests_no_primitive() {
        let torus = crate::scene::procedural::torus(glam::Vec3::ZERO, 2.0, 0.5, 100, 50).triangles();
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
        let shapes: Vec<Shape> = parts.prims.iter().map(|p| p.shape.clone()).collect();
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

    /// Rays leaving the room's own faces, to either side (a camera or a
    /// light outside a closed room sends such rays from the walls' outer
    /// sides): the enclosure finds what the triangles find. A ray leaving a
    /// face outwards used to be taken for one inside the room, and met a
    /// wall it could never reach.
    #[test]
    fn rays_leaving_a_face_outwards_meet_nothing_of_the_room() {
        use crate::math::offset_ray_origin;
        use crate::scene::{Eye, Scene};
        let parts = Scene::tncg15_parts(Eye::One);
        let room: Vec<Shape> = parts.prims[..24].iter().map(|p| p.shape.clone()).collect();
        let group: Vec<Option<u32>> = vec![Some(0); 24];
        let plain = Accel::new(room.clone());
        let fast = Accel::with_enclosure(room.clone(), &group);
        assert!(fast.enclosure().is_some());
        let mut rng = stream(17, Domain::Camera, 0);
        let (mut outward, mut inward) = (0, 0);
        for i in 0..40_000 {
            let prim = i % 24;
            let Shape::Triangle(t) = room[prim] else { unreachable!() };
            let w = next_2d(&mut rng);
            let (u, v) = if w.x + w.y > 1.0 { (1.0 - w.x, 1.0 - w.y) } else { (w.x, w.y) };
            let h = t.record(1.0, u, v);
            let dir = uniform_cone(next_2d(&mut rng), -1.0);
            let origin = offset_ray_origin(h.point, h.p_err, h.normal, dir);
            let ray = Ray::new(origin, dir);
            let dep = Departure { prim: prim as u32, outward: dir.dot(h.normal) > 0.0 };
            let (a, b) =
                (plain.closest_hit(&ray, Some(dep), f32::INFINITY), fast.closest_hit(&ray, Some(dep), f32::INFINITY));
            // Room normals point inwards: leaving against one is leaving the room.
            if dep.outward {
                inward += 1;
                assert!(b.is_some(), "{ray:?} from prim {prim}");
            } else {
                outward += 1;
                assert!(a.is_none() && b.is_none(), "{ray:?} from prim {prim}: {a:?} / {b:?}");
                assert!(!fast.occluded(&ray, Some(dep), 100.0, None));
            }
        }
        assert!(outward > 15_000 && inward > 15_000);
    }

    /// A triangle lying on a face of the enclosure (a rug on the floor)
    /// is what rays see there, not the face under it.
    #[test]
    fn a_rug_on_the_floor_wins_over_the_floor() {
        use crate::scene::{Eye, Scene};
        let parts = Scene::tncg15_parts(Eye::One);
        let mut shapes: Vec<Shape> = parts.prims.iter().map(|p| p.shape.clone()).collect();
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
        let torus = crate::scene::procedural::torus(glam::Vec3::ZERO, 2.0, 0.5, 100, 50).triangles();
        let shapes: Vec<Shape> = torus.iter().map(|[a, b, c]| Shape::Triangle(Triangle::new(*a, *b, *c))).collect();
        let tree = Accel::new(shapes.clone());
        assert!(tree.bvh.len() > 100, "{} nodes", tree.bvh.len());
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
