//! A closed convex room drawn with triangles (the TNCG15 room, a Cornell
//! box) taken as what it is: the intersection of its planes' half-spaces.
//!
//! The room's walls are a scene's largest primitives, and nearly every ray
//! ends on one of them; but in a BVH their boxes span the whole scene, so a
//! ray visits most of the tree before it reaches them (10.6 nodes and 2.4
//! triangles per random ray in the default room). Seen as a convex
//! polyhedron, the wall a ray meets from inside is the plane it crosses
//! first on its way out: one signed distance and one division per plane,
//! four planes per SIMD step, no tree. It is watertight by construction: a
//! ray inside always leaves through some plane, edges and corners included.
//!
//! Detection is exact or nothing. Triangles become an enclosure only when
//! (1) each of its planes has every primitive of the scene on one side,
//! (2) the polyhedron those half-spaces bound is finite and the triangles on
//! each plane tile its face there (no two overlap, and their areas add up
//! to the face's), and (3) the triangles of a face share a material and none
//! is a light. Anything else stays in the BVH, and so do triangles lying on
//! a face but not part of its tiling (the tetrahedron's base on the floor).

use crate::math::{gamma, Ray};
use crate::shape::{Shape, ShapeHit, Triangle, FLAT};
use glam::{Vec3, Vec4};

/// Distinct planes tried, those of the largest triangles first: detection
/// costs (planes tried) x (primitives), and a room's walls are its largest
/// triangles.
const MAX_CANDIDATES: usize = 64;
/// Faces at most (four SIMD lanes at a time).
const MAX_FACES: usize = 32;
/// Marks a primitive that is not part of the enclosure.
const NONE: u32 = u32::MAX;

#[derive(Clone, Copy, Debug)]
struct Face {
    /// Unit normal pointing into the enclosure, and the offset: the inside
    /// is `n . x >= d`.
    n: Vec3,
    d: f32,
    /// The primitive a hit on this face reports (the lowest index of its
    /// tiling; all share a material and none is a light), and that
    /// triangle's own normal. Which triangle of the face was hit is not
    /// tracked: nothing downstream depends on it (a per-triangle attribute,
    /// a texture, would need a 2D lookup here).
    prim: u32,
    normal: Vec3,
}

/// Four faces' planes in SIMD lanes; padding lanes (n = 0, d = -1) are
/// parallel to every ray and contain every point, so they constrain nothing.
#[derive(Clone, Copy, Debug)]
struct Lanes {
    nx: Vec4,
    ny: Vec4,
    nz: Vec4,
    d: Vec4,
    /// Each lane's face index (exact in f32; [`NO_FACE`] for padding), so
    /// that the faces are tracked in the same lanes as their distances.
    face: Vec4,
}

/// A face index no face has, as the lanes carry it.
const NO_FACE: f32 = 1.0e9;

pub struct Enclosure {
    faces: Vec<Face>,
    lanes: Vec<Lanes>,
    /// For each scene primitive, the face it tiles, or [`NONE`].
    face_of: Vec<u32>,
}

/// Where a ray meets the enclosure.
#[derive(Clone, Copy, Debug)]
pub struct EnclosureHit {
    pub t: f32,
    face: u32,
}

impl Enclosure {
    /// Finds the enclosure among `shapes`, if there is one. `group[i]` is
    /// the material of primitive `i`, or `None` where it may not be part of
    /// a face (a light: its hits must report it).
    pub fn detect(shapes: &[Shape], group: &[Option<u32>]) -> Option<Enclosure> {
        let (lo, hi) = shapes.iter().fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(a, b), s| {
            let (l, h) = s.bounds();
            (a.min(l), b.max(h))
        });
        let size = (hi - lo).length();
        if !(size > 0.0) || !size.is_finite() {
            return None;
        }
        // Coplanarity and containment tolerance: a few thousand ulps of the
        // scene's size, far below any feature a scene means to model.
        let eps = 1e-5 * size;
        let mut tris: Vec<(u32, Triangle, f32)> = shapes
            .iter()
            .zip(group)
            .enumerate()
            .filter_map(|(i, (s, g))| match s {
                Shape::Triangle(t) if t.normal != Vec3::ZERO && g.is_some() => Some((i as u32, *t, t.area())),
                _ => None,
            })
            .collect();
        tris.sort_by(|a, b| b.2.total_cmp(&a.2).then(a.0.cmp(&b.0)));
        let on_plane = |t: &Triangle, n: Vec3, d: f32| [t.v0, t.v1, t.v2].iter().all(|v| (n.dot(*v) - d).abs() <= eps);

        // Planes with the whole scene on one side, oriented towards it.
        let mut tried: Vec<(Vec3, f32)> = Vec::new();
        let mut planes: Vec<(Vec3, f32)> = Vec::new();
        for (_, t, _) in &tris {
            if tried.len() >= MAX_CANDIDATES {
                break;
            }
            if tried.iter().any(|&(n, d)| on_plane(t, n, d)) {
                continue;
            }
            let (n, d) = (t.normal, t.normal.dot(t.v0));
            tried.push((n, d));
            let (min, max) = shapes.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), s| {
                let (l, h) = s.extent_along(n);
                (a.min(l), b.max(h))
            });
            if min >= d - eps {
                planes.push((n, d));
            } else if max <= d + eps {
                planes.push((-n, -d));
            }
        }
        if planes.len() < 4 || planes.len() > MAX_FACES {
            return None;
        }

        let centre = 0.5 * (lo + hi);
        let mut faces = Vec::with_capacity(planes.len());
        let mut face_of = vec![NONE; shapes.len()];
        for (i, &(n, d)) in planes.iter().enumerate() {
            let polygon = face_polygon(&planes, i, centre, size)?;
            let area = polygon_area(&polygon, n);
            let (u, v) = plane_basis(n);
            let mut tiling: Vec<(u32, [[f32; 2]; 3])> = Vec::new();
            let mut covered = 0.0;
            let mut material = None;
            for (index, t, a) in &tris {
                if !on_plane(t, n, d) {
                    continue;
                }
                let flat = [t.v0, t.v1, t.v2].map(|p| [p.dot(u), p.dot(v)]);
                if tiling.iter().any(|(_, other)| overlap(other, &flat, eps)) {
                    continue;
                }
                let g = group[*index as usize];
                if material.is_some_and(|m| Some(m) != g) {
                    return None;
                }
                material = g;
                tiling.push((*index, flat));
                covered += a;
            }
            if !((covered - area).abs() <= 1e-4 * area) {
                return None;
            }
            let prim = tiling.iter().map(|(index, _)| *index).min()?;
            for (index, _) in &tiling {
                face_of[*index as usize] = i as u32;
            }
            let Shape::Triangle(rep) = shapes[prim as usize] else { return None };
            faces.push(Face { n, d, prim, normal: rep.normal });
        }
        let lanes = faces
            .chunks(4)
            .enumerate()
            .map(|(chunk, c)| {
                let base = 4 * chunk;
                let lane =
                    |f: fn(&Face) -> f32, pad: f32| Vec4::from_array(std::array::from_fn(|k| c.get(k).map_or(pad, f)));
                Lanes {
                    nx: lane(|f| f.n.x, 0.0),
                    ny: lane(|f| f.n.y, 0.0),
                    nz: lane(|f| f.n.z, 0.0),
                    d: lane(|f| f.d, -1.0),
                    face: Vec4::from_array(std::array::from_fn(
                        |k| {
                            if k < c.len() {
                                (base + k) as f32
                            } else {
                                NO_FACE
                            }
                        },
                    )),
                }
            })
            .collect();
        Some(Enclosure { faces, lanes, face_of })
    }

    /// Number of faces.
    pub fn faces(&self) -> usize {
        self.faces.len()
    }

    /// Whether primitive `prim` is part of the enclosure (and not in the BVH).
    pub fn contains(&self, prim: u32) -> bool {
        self.face_of(prim) != NONE
    }

    /// The face primitive `prim` tiles, or `u32::MAX`.
    pub fn face_of(&self, prim: u32) -> u32 {
        self.face_of.get(prim as usize).copied().unwrap_or(NONE)
    }

    /// Where the ray meets the enclosure in (0, t_max): leaving it from
    /// inside, or entering it from outside. `skip` is the face the ray
    /// leaves (`u32::MAX` if none): a ray never meets a plane it leaves again,
    /// and one that leaves a face towards the outside is outside a convex
    /// body, which it never meets again either.
    #[inline]
    pub fn hit(&self, ray: &Ray, skip: u32, t_max: f32) -> Option<EnclosureHit> {
        if self.leaves_outwards(ray, skip) {
            return None;
        }
        let (ox, oy, oz) = (Vec4::splat(ray.origin.x), Vec4::splat(ray.origin.y), Vec4::splat(ray.origin.z));
        let (dx, dy, dz) = (Vec4::splat(ray.dir.x), Vec4::splat(ray.dir.y), Vec4::splat(ray.dir.z));
        // u32::MAX becomes 2^32 in f32: no face's index.
        let skip_lane = Vec4::splat(skip as f32);
        // A ray from inside (inside every plane but the one it leaves) meets
        // the nearest plane it crosses out of: no plane can be entered
        // ahead of it, and none parallel to the ray can keep it out. Only
        // that is computed here; anything else takes the general path.
        let mut leaving = [Vec4::INFINITY; MAX_FACES / 4];
        let mut nearest = Vec4::INFINITY;
        let mut outside = glam::BVec4A::splat(false);
        for (l, leave) in self.lanes.iter().zip(leaving.iter_mut()) {
            let s = l.nx * ox + l.ny * oy + l.nz * oz - l.d;
            let rate = l.nx * dx + l.ny * dy + l.nz * dz;
            let keep = l.face.cmpne(skip_lane);
            outside |= s.cmplt(Vec4::ZERO) & keep;
            *leave = Vec4::select(rate.cmplt(Vec4::ZERO) & keep, -s / rate, Vec4::INFINITY);
            nearest = nearest.min(*leave);
        }
        if outside.any() {
            return self.hit_general(ray, skip, t_max);
        }
        let t = nearest.min_element();
        // The lowest face reaching it (a ray through an edge meets two);
        // lane k of chunk c is face 4c + k. Without a branch per chunk:
        // random rays would mispredict which chunk holds it.
        let reached = leaving[..self.lanes.len()]
            .iter()
            .enumerate()
            .fold(0u32, |m, (c, leave)| m | leave.cmpeq(Vec4::splat(t)).bitmask() << (4 * c));
        let face = reached.trailing_zeros();
        (t > 0.0 && t < t_max && (face as usize) < self.faces.len()).then_some(EnclosureHit { t, face })
    }

    /// Whether the ray leaves face `skip` towards the outside (or along it).
    #[inline]
    fn leaves_outwards(&self, ray: &Ray, skip: u32) -> bool {
        self.faces.get(skip as usize).is_some_and(|f| !(ray.dir.dot(f.n) > 0.0))
    }

    /// [`Enclosure::hit`] for any origin: inside, outside, or on a plane
    /// other than the one it leaves.
    #[cold]
    fn hit_general(&self, ray: &Ray, skip: u32, t_max: f32) -> Option<EnclosureHit> {
        if self.leaves_outwards(ray, skip) {
            return None;
        }
        let (ox, oy, oz) = (Vec4::splat(ray.origin.x), Vec4::splat(ray.origin.y), Vec4::splat(ray.origin.z));
        let (dx, dy, dz) = (Vec4::splat(ray.dir.x), Vec4::splat(ray.dir.y), Vec4::splat(ray.dir.z));
        let skip = Vec4::splat(skip as f32);
        // Lane-wise nearest plane crossed out of and farthest crossed into,
        // and their faces; reduced across lanes once, after the loop. (A
        // reduction per chunk, compared with the best so far, cost a branch
        // that random rays mispredict half the time: the room of 8 faces
        // alone took 39 ns per random ray that way, 29 ns this way.)
        let (mut out_t, mut out_face) = (Vec4::INFINITY, Vec4::splat(NO_FACE));
        let (mut in_t, mut in_face) = (Vec4::NEG_INFINITY, Vec4::splat(NO_FACE));
        let mut never = glam::BVec4A::splat(false);
        for l in &self.lanes {
            // Signed distance inside (>= 0 inside) and its rate along the ray.
            let s = l.nx * ox + l.ny * oy + l.nz * oz - l.d;
            let rate = l.nx * dx + l.ny * dy + l.nz * dz;
            let t = -s / rate;
            let keep = l.face.cmpne(skip);
            // Parallel to a plane and outside it: the ray never enters.
            never |= rate.cmpeq(Vec4::ZERO) & s.cmplt(Vec4::ZERO) & keep;
            // A lane's t is NaN only for rate = s = 0 (parallel, on the
            // plane), which neither mask selects. Strict comparisons keep
            // the earlier face on a tie.
            let leaving = Vec4::select(rate.cmplt(Vec4::ZERO) & keep, t, Vec4::INFINITY);
            let nearer = leaving.cmplt(out_t);
            out_t = Vec4::select(nearer, leaving, out_t);
            out_face = Vec4::select(nearer, l.face, out_face);
            let entering = Vec4::select(rate.cmpgt(Vec4::ZERO) & keep, t, Vec4::NEG_INFINITY);
            let farther = entering.cmpgt(in_t);
            in_t = Vec4::select(farther, entering, in_t);
            in_face = Vec4::select(farther, l.face, in_face);
        }
        if never.any() {
            return None;
        }
        // The lowest face index among the lanes that reach the extreme.
        let first = |t: Vec4, faces: Vec4, m: f32| {
            let f = Vec4::select(t.cmpeq(Vec4::splat(m)), faces, Vec4::splat(NO_FACE)).min_element();
            if f < NO_FACE {
                f as u32
            } else {
                NONE
            }
        };
        let t_out = out_t.min_element();
        let out_face = first(out_t, out_face, t_out);
        let t_in = in_t.max_element();
        let (t, face) = if t_in > 0.0 {
            let in_face = first(in_t, in_face, t_in);
            // From outside: it enters through the last plane it crosses in,
            // if that comes before the first it crosses out of. A ray through
            // an edge or a corner crosses both at once, and rounding must not
            // let it slip between them: where the order is within the two
            // distances' error bounds, it counts as a hit.
            if t_in > t_out && t_in - self.t_error(ray, in_face, t_in) > t_out + self.t_error(ray, out_face, t_out) {
                return None;
            }
            (t_in, in_face)
        } else {
            (t_out, out_face)
        };
        (t > 0.0 && t < t_max && face != NONE).then_some(EnclosureHit { t, face })
    }

    /// A bound on the rounding error of the distance `t` computed to face
    /// `f`'s plane: that of the signed distance (4 terms) and of the rate
    /// along the ray (3 terms), divided by the rate.
    fn t_error(&self, ray: &Ray, f: u32, t: f32) -> f32 {
        let Some(face) = self.faces.get(f as usize) else { return 0.0 };
        let s_err = gamma(5) * ((face.n * ray.origin).abs().element_sum() + face.d.abs());
        let rate_err = gamma(4) * (face.n * ray.dir).abs().element_sum();
        (s_err + t.abs() * rate_err) / face.n.dot(ray.dir).abs()
    }

    /// The hit's primitive and record. The point is `o + t d`: its distance
    /// to the plane carries the rounding of the plane's signed distance (4
    /// terms), of the rate (3 terms) and of the sum itself, all bounded by
    /// gamma(7) times the magnitudes below.
    pub fn record(&self, ray: &Ray, h: EnclosureHit) -> (u32, ShapeHit) {
        let f = &self.faces[h.face as usize];
        let step = ray.dir * h.t;
        let point = ray.origin + step;
        let p_err = gamma(7) * (ray.origin.abs() + step.abs() + Vec3::splat(f.d.abs()));
        (f.prim, ShapeHit { t: h.t, point, p_err, normal: f.normal, uv: [0.0; 2], shading: FLAT, shading_normal: None })
    }
}

/// Two unit vectors spanning the plane with normal `n`.
fn plane_basis(n: Vec3) -> (Vec3, Vec3) {
    let u = n.any_orthonormal_vector();
    (u, n.cross(u))
}

/// The polyhedron's face on plane `i`: a square far larger than the scene,
/// clipped by every other half-space (Sutherland–Hodgman). `None` when the
/// face is empty or reaches beyond the scene (the half-spaces leave the
/// polyhedron open there).
fn face_polygon(planes: &[(Vec3, f32)], i: usize, centre: Vec3, size: f32) -> Option<Vec<Vec3>> {
    let (n, d) = planes[i];
    let (u, v) = plane_basis(n);
    let c = centre - n * (n.dot(centre) - d);
    let r = 4.0 * size;
    let mut polygon = vec![c - r * u - r * v, c + r * u - r * v, c + r * u + r * v, c - r * u + r * v];
    for (j, &(m, e)) in planes.iter().enumerate() {
        if j == i {
            continue;
        }
        let mut clipped = Vec::with_capacity(polygon.len() + 1);
        for k in 0..polygon.len() {
            let (a, b) = (polygon[k], polygon[(k + 1) % polygon.len()]);
            let (sa, sb) = (m.dot(a) - e, m.dot(b) - e);
            if sa >= 0.0 {
                clipped.push(a);
            }
            if (sa >= 0.0) != (sb >= 0.0) {
                clipped.push(a + (b - a) * (sa / (sa - sb)));
            }
        }
        polygon = clipped;
    }
    let bounded = polygon.len() >= 3 && polygon.iter().all(|p| (*p - centre).length() <= size);
    bounded.then_some(polygon)
}

fn polygon_area(polygon: &[Vec3], n: Vec3) -> f32 {
    let twice: f32 = (0..polygon.len()).map(|k| polygon[k].cross(polygon[(k + 1) % polygon.len()]).dot(n)).sum();
    0.5 * twice.abs()
}

/// Whether two triangles in one plane (in its 2D coordinates) share more
/// than an edge or a point: no edge direction of either separates them, to
/// within `eps`.
fn overlap(a: &[[f32; 2]; 3], b: &[[f32; 2]; 3], eps: f32) -> bool {
    let separates = |p: [f32; 2], q: [f32; 2]| {
        let axis = glam::Vec2::new(q[1] - p[1], p[0] - q[0]).normalize_or_zero();
        let project = |t: &[[f32; 2]; 3]| {
            t.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
                let x = axis.dot(glam::Vec2::from(*v));
                (lo.min(x), hi.max(x))
            })
        };
        let ((a0, a1), (b0, b1)) = (project(a), project(b));
        a1 <= b0 + eps || b1 <= a0 + eps
    };
    let edges = |t: &[[f32; 2]; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
    !edges(a).into_iter().chain(edges(b)).any(|(p, q)| separates(p, q))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Eye, Scene};

    fn room_shapes() -> (Vec<Shape>, Vec<Option<u32>>) {
        let parts = Scene::tncg15_parts(Eye::One);
        let shapes: Vec<Shape> = parts.prims.iter().map(|p| p.shape.clone()).collect();
        let group = parts.prims.iter().map(|p| Some(p.material)).collect();
        (shapes, group)
    }

    #[test]
    fn the_tncg15_room_is_an_enclosure_of_eight_faces() {
        let (shapes, group) = room_shapes();
        let e = Enclosure::detect(&shapes, &group).expect("the room is closed and convex");
        assert_eq!(e.faces(), 8);
        // The 24 room triangles tile it; the spheres and the tetrahedron
        // (whose base lies on the floor) do not.
        assert!((0..24).all(|i| e.contains(i)));
        assert!((24..shapes.len() as u32).all(|i| !e.contains(i)));
    }

    /// The path for rays from inside must answer exactly as the general
    /// one: rays from inside, from outside, and leaving a face from a
    /// point on it (its own plane skipped, near edges and corners too).
    #[test]
    fn rays_from_inside_meet_the_face_the_general_path_finds() {
        use crate::sampling::{next_2d, stream, uniform_cone, Domain};
        let (shapes, group) = room_shapes();
        let e = Enclosure::detect(&shapes, &group).unwrap();
        let mut rng = stream(17, Domain::Camera, 0);
        let (mut inside, mut on_face) = (0, 0);
        for i in 0..300_000 {
            let (a, b) = (next_2d(&mut rng), next_2d(&mut rng));
            let dir = uniform_cone(next_2d(&mut rng), -1.0);
            let (origin, skip) = if i % 2 == 0 {
                // Anywhere in a box a little larger than the room.
                (Vec3::new(-4.0 + 18.0 * a.x, -7.0 + 14.0 * a.y, -6.0 + 12.0 * b.x), NONE)
            } else {
                // On a wall triangle (corners and edges included), leaving it.
                let prim = (b.y * 24.0) as usize % 24;
                let Shape::Triangle(t) = shapes[prim] else { unreachable!() };
                let (u, v) = if a.x + a.y > 1.0 { (1.0 - a.x, 1.0 - a.y) } else { (a.x, a.y) };
                let (u, v) = if b.x < 0.1 { (u.round(), v.round() * (1.0 - u.round())) } else { (u, v) };
                (t.v0 + u * (t.v1 - t.v0) + v * (t.v2 - t.v0), e.face_of(prim as u32))
            };
            let ray = Ray::new(origin, dir);
            let fast = e.hit(&ray, skip, f32::INFINITY).map(|h| (h.t, h.face));
            let general = e.hit_general(&ray, skip, f32::INFINITY).map(|h| (h.t, h.face));
            assert_eq!(fast, general, "{ray:?} leaving face {skip}");
            if skip != NONE && !(dir.dot(e.faces[skip as usize].n) > 0.0) {
                // Leaving the room through its own face: outside, for good.
                assert_eq!(fast, None, "{ray:?} left face {skip} outwards");
                continue;
            }
            inside += fast.is_some() as u32;
            on_face += (skip != NONE && fast.is_some()) as u32;
        }
        assert!(inside > 150_000 && on_face > 60_000, "{inside} {on_face}");
    }

    #[test]
    fn an_open_or_holed_or_mixed_room_is_not_an_enclosure() {
        let (shapes, group) = room_shapes();
        // A wall triangle missing: the face is not tiled.
        let mut holed = shapes.clone();
        holed.remove(12);
        let mut g = group.clone();
        g.remove(12);
        assert!(Enclosure::detect(&holed, &g).is_none());
        // A wall triangle that is a light.
        let mut lit = group.clone();
        lit[13] = None;
        assert!(Enclosure::detect(&shapes, &lit).is_none());
        // Two materials on one wall.
        let mut mixed = group.clone();
        mixed[12] = Some(99);
        assert!(Enclosure::detect(&shapes, &mixed).is_none());
        // The ceiling lifted at one corner triangle: no longer one plane.
        let mut bent = shapes.clone();
        if let Shape::Triangle(t) = bent[6] {
            bent[6] = Shape::Triangle(Triangle::new(t.v0 + Vec3::Z * 0.5, t.v1, t.v2));
        }
        assert!(Enclosure::detect(&bent, &group).is_none());
        // Without the ceiling the polyhedron is open.
        let open: Vec<Shape> =
            shapes.iter().enumerate().filter(|(i, _)| !(6..12).contains(i)).map(|(_, s)| s.clone()).collect();
        let og: Vec<Option<u32>> =
            group.iter().enumerate().filter(|(i, _)| !(6..12).contains(i)).map(|(_, g)| *g).collect();
        assert!(Enclosure::detect(&open, &og).is_none());
    }

    #[test]
    fn a_sphere_poking_through_a_wall_breaks_the_enclosure() {
        let (mut shapes, mut group) = room_shapes();
        shapes.push(Shape::Sphere(crate::shape::Sphere { center: Vec3::new(5.0, 0.0, 4.8), radius: 0.5 }));
        group.push(Some(0));
        assert!(Enclosure::detect(&shapes, &group).is_none());
    }

    #[test]
    fn overlapping_and_touching_triangles() {
        let a = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let shares_edge = [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let shares_point = [[1.0, 0.0], [2.0, 0.0], [2.0, 1.0]];
        let inside = [[0.1, 0.1], [0.3, 0.1], [0.1, 0.3]];
        assert!(!overlap(&a, &shares_edge, 1e-6));
        assert!(!overlap(&a, &shares_point, 1e-6));
        assert!(overlap(&a, &inside, 1e-6));
        assert!(overlap(&a, &a, 1e-6));
    }
}
