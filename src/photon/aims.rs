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
/// within twice that height. Beyond an edge nothing is met (or a surface
/// facing elsewhere); under an object standing on the surface, its
/// underside is met.
pub fn disk_coverage(scene: &Scene, x: Vertex, n: Vec3, r: f32, samples: u32) -> f32 {
    if !(r > 0.0) || samples == 0 {
        return 1.0;
    }
    let frame = Frame::from_normal(n);
    let height = 0.05 * r + 1e-5 * x.abs().max_element();
    let mut on = 0;
    for i in 0..samples {
        // A Fermat spiral: equal areas per sample, no random numbers.
        let radius = r * ((i as f32 + 0.5) / samples as f32).sqrt();
        let angle = i as f32 * 2.399_963;
        let q = x + radius * (angle.cos() * frame.s + angle.sin() * frame.t);
        let ray = Ray::new(q + height * n, -n);
        if let Some(h) = scene.intersect(&ray, None) {
            let facing = if h.normal.dot(n) >= 0.0 { h.normal } else { -h.normal };
            let same_side = h.normal.dot(-n) < 0.0;
            on += (h.t <= 2.0 * height && same_side && facing.dot(n) >= NORMAL_COSINE) as u32;
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
