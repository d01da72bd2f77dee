//! photonmap: Jensen-style photon mapping for the TNCG15 hexagonal room, and
//! the CS475 Whitted ray tracer (`trace`) over the same core.
//!
//! Data flows one way: scene (built in, or a TOML file: [`scene::file`]) →
//! accelerator → photon maps → integrator → film → image file; `trace`
//! skips the photon maps ([`integrator::whitted`]).
//!
//! Where the course's classes live (TNCG15 lecture 6):
//! * `Vertex`, `Direction`, `ColorDbl`: [`math::Vertex`], [`math::Direction`], [`math::Color`];
//! * `Ray`: [`math::Ray`]; local frames for reflection: [`math::Frame`], [`optics`];
//! * `Triangle` (Möller–Trumbore), spheres, tetrahedra: [`shape`]; the CS475
//!   transformed unit sphere: [`shape::Ellipsoid`];
//! * materials, including CS475's Phong (m_a, m_l, m_s, m_sm, m_sp, m_r): [`material`];
//! * lights (disk, emissive triangle, point with falloff, directional): [`light`];
//! * `Scene`: [`scene::Scene`] (the room: [`scene::Scene::tncg15`]);
//! * `Camera`, `Pixel`: [`camera::Camera`], [`film::Film`], [`render`].

// `!(x > 0.0)` is written on purpose throughout: unlike `x <= 0.0` it also
// rejects NaN, which is how the numerics stop a bad value at its source.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accel;
pub mod camera;
pub mod command;
pub mod display;
pub mod envmap;
pub mod error;
pub mod export;
pub mod film;
pub mod filter;
pub mod integrator;
pub mod interrupt;
pub mod light;
pub mod material;
pub mod math;
pub mod medium;
pub mod memory;
pub mod metrics;
pub mod optics;
pub mod output;
pub mod photon;
pub mod progress;
pub mod provenance;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod shape;
pub mod stats;
pub mod suite;
pub mod texture;

/// Every setting that decides a render ([`render::settings`]), at the
/// crate's top as the programs and tests name it.
pub use render::settings;
