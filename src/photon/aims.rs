//! What photon mapping derives from a scene: the spheres its caustic
//! photons and aimed gather rays go towards, the maps the scene needs, and
//! the part of an estimate's disk that lies on its surface. The scene
//! itself knows nothing of photons.

use super::map::NORMAL_COSINE;
use crate::math::{max_component, Frame, Ray, Vertex};
use crate::scene::Scene;
use glam::Vec3;
use std::collections::BTreeMap;

/// A bounding sphere of an object with a mirror or glass lobe, for aiming
/// caustic photons: one per object (a mesh of a million triangles is one
/// target), so that the cost of aiming a photon and the share of photons an
/// object gets do not grow with its triangles.
#[derive(Clone, Copy, Debug)]
pub struct Target {
    pub center: Vertex,
    pub radius: f32,
    /// The object it bounds.
    pub object: u32,
}

impl Target {
    /// The cone from `from` that just contains the target's sphere
    /// ([`crate::sampling::cone_to_sphere`]).
    pub fn cone_from(&self, from: Vec3) -> (Vec3, f32) {
        crate::sampling::cone_to_sphere(from, self.center, self.radius)
    }
}

/// One bounding sphere per object with a mirror or glass lobe, in the order
/// of the objects: centred on the object's box, holding every primitive's
/// own bounding sphere.
pub fn specular_targets(scene: &Scene) -> Vec<Target> {
    let specular: Vec<u32> =
        (0..scene.prim_count() as u32).filter(|&p| scene.material(p).has_specular_lobe()).collect();
    let mut boxes: BTreeMap<u32, (Vec3, Vec3)> = BTreeMap::new();
    for &p in &specular {
        let (lo, hi) = scene.shape(p).bounds();
        let b = boxes.entry(scene.object(p)).or_insert((lo, hi));
        *b = (b.0.min(lo), b.1.max(hi));
    }
    let mut targets: BTreeMap<u32, Target> = boxes
        .into_iter()
        .map(|(object, (lo, hi))| (object, Target { center: 0.5 * (lo + hi), radius: 0.0, object }))
        .collect();
    for &p in &specular {
        let (c, r) = scene.shape(p).bounding_sphere();
        if let Some(t) = targets.get_mut(&scene.object(p)) {
            t.radius = t.radius.max(c.distance(t.center) + r);
        }
    }
    targets.into_values().collect()
}

/// The parts of light transport a scene can have (see [`needs`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Needs {
    /// Light reaching diffuse surfaces through mirrors or glass.
    pub caustics: bool,
    /// Light reflected between diffuse surfaces.
    pub global: bool,
}

/// What a scene's light transport can need (its `targets` being its
/// [`specular_targets`]), so that a render skips the rest.
pub fn needs(scene: &Scene, targets: &[Target]) -> Needs {
    let lit = max_component(scene.emitted_power()) > 0.0;
    let diffuse = (0..scene.prim_count() as u32).any(|p| scene.material(p).diffuse_rho().is_some());
    // Paths of at most two vertices (lights seen, direct light) read no map.
    let lit = lit && scene.paths.max_depth.is_none_or(|d| d > 2);
    Needs {
        // Caustic paths need a mirror or glass object and a diffuse
        // surface to land on.
        caustics: lit && diffuse && !targets.is_empty(),
        // Indirect diffuse light needs light reflected by a diffuse
        // surface (a black room has none).
        global: lit && diffuse,
    }
}

/// The fraction of the disk of radius `r` around `x`, in the plane of
/// unit normal `n` (x's surface, on the side `n` faces), that lies on a
/// surface facing like x's: the part of a density estimate's disk that
/// can hold its photons. Measured at a fixed pattern of `samples` points:
/// each counts where a short ray down from just above it meets a surface
/// facing as the estimates count one as the same ([`NORMAL_COSINE`])
/// within twice that height, wound as x's own surface is. Beyond an edge
/// nothing is met (or a surface facing elsewhere); under an object
/// standing on the surface, its underside is met, wound the other way.
/// The winding is compared with x's own surface's, met by the same ray
/// down at x, not with `n`: `n` faces the side the photons came from,
/// which a surface's winding need not (a room's wall may be wound either
/// way), and a wall wound outwards measured none of its disk.
pub fn disk_coverage(scene: &Scene, x: Vertex, n: Vec3, r: f32, samples: u32) -> f32 {
    if !(r > 0.0) || samples == 0 {
        return 1.0;
    }
    let frame = Frame::from_normal(n);
    let height = 0.05 * r + 1e-5 * x.abs().max_element();
    // The geometric normal of a surface facing like x's met straight
    // down from just above `q`, if any.
    let down = |q: Vec3| {
        let h = scene.intersect(&Ray::new(q + height * n, -n), None).filter(|h| h.t <= 2.0 * height)?;
        (h.normal.dot(n).abs() >= NORMAL_COSINE).then_some(h.normal)
    };
    // x's own winding, from x, else from the first point of the spiral
    // that meets a surface (an x on an edge may meet none).
    let mut wound = down(x);
    let mut on = 0;
    for i in 0..samples {
        // A Fermat spiral: equal areas per sample, no random numbers.
        let radius = r * ((i as f32 + 0.5) / samples as f32).sqrt();
        let angle = i as f32 * 2.399_963;
        let q = x + radius * (angle.cos() * frame.s + angle.sin() * frame.t);
        if let Some(normal) = down(q) {
            on += (normal.dot(*wound.get_or_insert(normal)) > 0.0) as u32;
        }
    }
    on as f32 / samples as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Eye;

    #[test]
    fn disk_coverage_is_the_part_of_the_disk_on_the_surface() {
        let scene = Scene::tncg15(Eye::One);
        let up = Vec3::Z;
        let cover = |x: Vec3, n: Vec3| disk_coverage(&scene, x, n, 0.5, 256);
        assert_eq!(cover(Vec3::new(5.0, 0.0, -5.0), up), 1.0);
        // The wall P1-P2 is y = 6 for x in [0, 10].
        let foot = cover(Vec3::new(5.0, 6.0, -5.0), up);
        assert!((foot - 0.5).abs() < 0.03, "{foot}");
        // The corner P2: walls P1-P2 (y = 6) and P2-P3 meet at (10, 6); the
        // angle there is 116.6 degrees, so a little under a third of the disk.
        let corner = cover(Vec3::new(10.0, 6.0, -5.0), up);
        let want = (180.0 - 63.43) / 360.0;
        assert!((corner - want).abs() < 0.03, "{corner} vs {want}");
        // Beside the tetrahedron's base (A, B at x = 10.8): partly under it.
        let under = cover(Vec3::new(10.9, 0.0, -5.0), up);
        assert!(under > 0.1 && under < 0.9, "{under}");
        // On a wall, facing into the room.
        assert_eq!(cover(Vec3::new(5.0, 6.0, 0.0), -Vec3::Y), 1.0);
    }

    /// A wall wound towards the room or away from it: the same coverage
    /// on either (photons face the side they came from, whatever the
    /// winding), and the floor's at the wall's foot the same too.
    #[test]
    fn disk_coverage_does_not_depend_on_winding() {
        let room = |wall: &str| {
            let text = format!(
                "[camera]\neye = [2, -3, 1]\ntarget = [2, 2, 1]\nup = [0, 0, 1]\nvfov = 60\nwidth = 8\nheight = 8\n\
                 [materials.grey]\ntype = \"lambertian\"\nrho = [0.5, 0.5, 0.5]\n\
                 [[shapes]]\ntype = \"quad\"\nvertices = [[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]]\nmaterial = \"grey\"\n\
                 [[shapes]]\ntype = \"quad\"\nvertices = {wall}\nmaterial = \"grey\"\n\
                 [[lights]]\ntype = \"point\"\nposition = [2, 2, 2]\ncolor = [1, 1, 1]\n"
            );
            let file = crate::scene::file::parse(&text, std::path::Path::new("room.toml")).expect("a valid scene");
            Scene::from_parts(file.parts)
        };
        // The east wall x = 4, wound towards the room (-x) and away (+x).
        let inwards = room("[[4, 0, 0], [4, 0, 3], [4, 4, 3], [4, 4, 0]]");
        let outwards = room("[[4, 0, 0], [4, 4, 0], [4, 4, 3], [4, 0, 3]]");
        for scene in [&inwards, &outwards] {
            let cover = |x: Vec3, n: Vec3| disk_coverage(scene, x, n, 0.5, 256);
            let wall_foot = cover(Vec3::new(4.0, 2.0, 0.0), -Vec3::X);
            assert!((wall_foot - 0.5).abs() < 0.03, "{wall_foot}");
            assert_eq!(cover(Vec3::new(4.0, 2.0, 1.5), -Vec3::X), 1.0);
            let floor_by_wall = cover(Vec3::new(4.0, 2.0, 0.0), Vec3::Z);
            assert!((floor_by_wall - 0.5).abs() < 0.03, "{floor_by_wall}");
        }
    }

    /// A target per object with a mirror or glass lobe, holding every such
    /// primitive of its object.
    #[test]
    fn every_specular_primitive_lies_in_its_objects_target() {
        let scene = Scene::tncg15(Eye::One);
        let targets = specular_targets(&scene);
        assert!(!targets.is_empty());
        for p in 0..scene.prim_count() as u32 {
            if !scene.material(p).has_specular_lobe() {
                continue;
            }
            let t = targets.iter().find(|t| t.object == scene.object(p)).expect("its object is a target");
            let (c, r) = scene.shape(p).bounding_sphere();
            assert!(c.distance(t.center) + r <= t.radius * (1.0 + 1e-6), "primitive {p} outside its target");
        }
        let n = needs(&scene, &targets);
        assert!(n.caustics && n.global);
    }
}
