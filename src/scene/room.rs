//! The built-in default scene: the TNCG15 hexagonal room of
//! notes/default-scene.md, number for number.

use super::{Prim, Scene, SceneParts};
use crate::camera::Camera;
use crate::light::{AreaLight, Emitting};
use crate::material::Material;
use crate::math::Color;
use crate::shape::{tetrahedron, Disk, Shape, Sphere, Triangle};
use glam::{Vec2, Vec3};

/// The eye positions of the course's camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Eye {
    /// e1 = (-2, 0, 0): 53.13 degree view (the default).
    One,
    /// e2 = (-1, 0, 0): 90 degree view.
    Two,
}

/// The TNCG15 hexagonal room (notes/default-scene.md) as 24 triangles whose
/// normals point into the room: floor and ceiling as fans of six around the
/// hexagon's centre, then two triangles per wall, walls in the spec's order
/// P0-P1 … P5-P0.
pub fn tncg15_room(floor: u32, ceiling: u32, walls: [u32; 6], object: u32) -> Vec<Prim> {
    let hexagon = [
        Vec2::new(-3.0, 0.0),
        Vec2::new(0.0, 6.0),
        Vec2::new(10.0, 6.0),
        Vec2::new(13.0, 0.0),
        Vec2::new(10.0, -6.0),
        Vec2::new(0.0, -6.0),
    ];
    let (floor_z, ceiling_z) = (-5.0, 5.0);
    let mut prims = Vec::with_capacity(24);
    let inside = Vec3::new(5.0, 0.0, 0.0);
    let mut room_triangle = |a: Vec3, b: Vec3, c: Vec3, material: u32| {
        let t = Triangle::new(a, b, c);
        let t = if t.normal.dot(inside - a) < 0.0 { Triangle::new(a, c, b) } else { t };
        prims.push(Prim { shape: Shape::Triangle(t), material, object });
    };
    let centre = Vec2::new(5.0, 0.0);
    for (z, material) in [(floor_z, floor), (ceiling_z, ceiling)] {
        for i in 0..6 {
            let (a, b) = (hexagon[i], hexagon[(i + 1) % 6]);
            room_triangle(centre.extend(z), a.extend(z), b.extend(z), material);
        }
    }
    for (i, m) in walls.into_iter().enumerate() {
        let (a, b) = (hexagon[i], hexagon[(i + 1) % 6]);
        room_triangle(a.extend(floor_z), b.extend(floor_z), b.extend(ceiling_z), m);
        room_triangle(a.extend(floor_z), b.extend(ceiling_z), a.extend(ceiling_z), m);
    }
    prims
}

impl Scene {
    /// The built-in TNCG15 room (see notes/default-scene.md), 800 x 800.
    pub fn tncg15(eye: Eye) -> Self {
        Scene::from_parts(Scene::tncg15_parts(eye))
    }

    /// The built-in room's primitives, materials, light and camera, before
    /// assembly: tests vary them (scale the scene, change a material).
    pub fn tncg15_parts(eye: Eye) -> SceneParts {
        let grey = Color::splat(0.8);
        let wall_rho = [
            Color::new(0.80, 0.10, 0.80), // P0-P1 back-left, magenta
            Color::new(0.80, 0.10, 0.10), // P1-P2 left, red
            Color::new(0.80, 0.80, 0.10), // P2-P3 front-left, yellow
            Color::new(0.10, 0.30, 0.80), // P3-P4 front-right, blue
            Color::new(0.10, 0.80, 0.10), // P4-P5 right, green
            Color::new(0.10, 0.80, 0.80), // P5-P0 back-right, cyan
        ];
        let mut materials = vec![Material::Lambertian { rho: grey }];
        let mut walls = [0u32; 6];
        for (wall, rho) in walls.iter_mut().zip(wall_rho) {
            materials.push(Material::Lambertian { rho });
            *wall = materials.len() as u32 - 1;
        }
        let mut prims = tncg15_room(0, 0, walls, 0);
        materials.push(Material::glass(1.5));
        let glass = materials.len() as u32 - 1;
        prims.push(Prim {
            shape: Shape::Sphere(Sphere { center: Vec3::new(9.5, -2.0, -3.0), radius: 1.5 }),
            material: glass,
            object: 1,
        });
        materials.push(Material::Mirror { reflectance: Color::splat(0.95) });
        let mirror = materials.len() as u32 - 1;
        prims.push(Prim {
            shape: Shape::Sphere(Sphere { center: Vec3::new(10.0, 2.5, -3.6), radius: 1.4 }),
            material: mirror,
            object: 2,
        });
        materials.push(Material::Lambertian { rho: Color::new(0.9, 0.6, 0.1) });
        let tet = materials.len() as u32 - 1;
        for t in tetrahedron(
            Vec3::new(10.8, -1.0, -5.0),
            Vec3::new(10.8, 1.0, -5.0),
            Vec3::new(12.4, 0.0, -5.0),
            Vec3::new(11.3, 0.0, -2.5),
        ) {
            prims.push(Prim { shape: Shape::Triangle(t), material: tet, object: 3 });
        }
        let light = Disk { center: Vec3::new(8.0, 0.0, 4.999), normal: -Vec3::Z, radius: 1.0 };
        let eye_point = match eye {
            Eye::One => Vec3::new(-2.0, 0.0, 0.0),
            Eye::Two => Vec3::new(-1.0, 0.0, 0.0),
        };
        let camera = Camera::from_corners(
            eye_point,
            // The image plane x = 0; seen from the eye, +y is left and +z up.
            [
                Vec3::new(0.0, -1.0, -1.0),
                Vec3::new(0.0, 1.0, -1.0),
                Vec3::new(0.0, 1.0, 1.0),
                Vec3::new(0.0, -1.0, 1.0),
            ],
            800,
            800,
        );
        SceneParts {
            prims,
            shading_normals: Vec::new(),
            materials,
            lights: vec![AreaLight::unplaced(Emitting::Disk(light), Color::splat(10.0), None)],
            ambient: Color::ZERO,
            camera,
            one_sided: Vec::new(),
            paths: crate::scene::PathLimits::default(),
            texturing: Default::default(),
            media: Default::default(),
        }
    }
}
