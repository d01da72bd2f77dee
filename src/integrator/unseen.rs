//! Light a path tracer cannot find: a point or directional (delta) light
//! is reached from a camera path only by a shadow ray, and no shadow ray
//! passes a mirror or glass, so whatever of its power first meets a
//! specular surface (its caustics, its image in a mirror) is missing from a
//! path-traced image. A point light inside a glass sphere renders black.
//! Photon mapping carries that light forward from the light and finds it.

use crate::scene::Scene;
use glam::Vec2;

/// Rays traced from each delta light, on a stratified grid of its
/// emission's two random numbers (the same grid for position and direction).
const GRID: u32 = 32;

/// What share of a delta light's emitted power first meets a mirror or
/// glass surface (of the power that meets anything).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularShare {
    /// The light's index in `Scene::lights`.
    pub light: usize,
    /// From 0 to 1; 1: the light reaches the scene only through mirrors
    /// and glass, and a path tracer renders none of it.
    pub share: f32,
}

/// For every delta light that meets any surface, the share of its power
/// whose first surface is specular, estimated from `GRID`² emitted rays
/// (exact for an enclosed light: every ray then meets the enclosure).
pub fn specular_shares(scene: &Scene) -> Vec<SpecularShare> {
    let mut shares = Vec::new();
    for (light, l) in scene.lights.iter().enumerate().filter(|(_, l)| l.is_delta()) {
        let (mut met, mut specular) = (0u32, 0u32);
        for i in 0..GRID * GRID {
            let u = Vec2::new(((i % GRID) as f32 + 0.5) / GRID as f32, ((i / GRID) as f32 + 0.5) / GRID as f32);
            // The position's numbers run across the grid the other way, so
            // a directional light's rays cover its disk and directions alike.
            // Only where the ray goes counts, not what it carries.
            let emitted = l.sample_le(Vec2::new(u.y, u.x), u);
            if let Some(hit) = scene.intersect(&emitted.ray, emitted.departure) {
                met += 1;
                specular += scene.material(hit.prim).is_specular() as u32;
            }
        }
        if met > 0 {
            shares.push(SpecularShare { light, share: specular as f32 / met as f32 });
        }
    }
    shares
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{Light, PointLight};
    use crate::material::Material;
    use crate::scene::{Eye, Prim, Scene};
    use crate::shape::{Shape, Sphere};
    use glam::Vec3;

    fn room_with_point_light(in_glass: bool) -> Scene {
        let mut parts = Scene::tncg15_parts(Eye::One);
        parts.lights.clear();
        let position = Vec3::new(6.0, 0.0, 0.0);
        parts.lights.push(Light::Point(PointLight {
            position,
            intensity: Vec3::splat(10.0),
            falloff: 2.0,
            dead_distance: 0.0,
        }));
        if in_glass {
            parts.materials.push(Material::glass(1.5));
            let glass = parts.materials.len() as u32 - 1;
            let shape = Shape::Sphere(Sphere { center: position, radius: 0.5 });
            parts.prims.push(Prim { shape, material: glass, object: 100 });
        }
        Scene::from_parts(parts)
    }

    #[test]
    fn a_point_light_in_glass_is_all_specular_and_in_the_open_room_partly() {
        let enclosed = specular_shares(&room_with_point_light(true));
        assert_eq!(enclosed, vec![SpecularShare { light: 0, share: 1.0 }]);
        let open = specular_shares(&room_with_point_light(false));
        assert_eq!(open.len(), 1);
        // The room's glass and mirror spheres take a part of the sphere of
        // directions, the walls the rest.
        assert!(open[0].share > 0.0 && open[0].share < 0.2, "{open:?}");
    }

    #[test]
    fn area_lights_are_not_delta_lights() {
        assert!(specular_shares(&Scene::tncg15(Eye::One)).is_empty());
    }
}
