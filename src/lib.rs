//! photonmap: Jensen-style photon mapping for the TNCG15 hexagonal room.
//!
//! Data flows one way: scene → accelerator → photon maps → integrator →
//! film → image file.
//!
//! Where the course's classes live (TNCG15 lecture 6):
//! * `Vertex`, `Direction`, `ColorDbl`: [`math::Vertex`], [`math::Direction`], [`math::Color`];
//! * `Ray`: [`math::Ray`]; local frames for reflection: [`math::Frame`], [`optics`];
//! * `Triangle` (Möller–Trumbore), spheres, tetrahedra: [`shape`];
//! * `Scene`: [`scene::Scene`] (the room: [`scene::Scene::tncg15`]);
//! * `Camera`, `Pixel`: [`camera::Camera`], [`film::Film`], [`render`].

pub mod accel;
pub mod camera;
pub mod error;
pub mod film;
pub mod integrator;
pub mod light;
pub mod material;
pub mod math;
pub mod metrics;
pub mod optics;
pub mod output;
pub mod photon;
pub mod progress;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod shape;
