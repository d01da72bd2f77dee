//! The render methods that prepare nothing before their camera pass: path
//! tracing and the Whitted tracer.

use super::camera_pass::{CameraPass, Placement};
use super::method::{shoot, Method, RenderMethod};
use crate::film::Film;
use crate::integrator::path::PathIntegrator;
use crate::integrator::whitted::Whitted;
use crate::progress::Mode;
use crate::scene::Scene;
use crate::stats::Stats;

/// Path tracing with next-event estimation.
pub struct PathTracing {
    pub shadow_rays: u32,
    pub skip: bool,
}

impl RenderMethod for PathTracing {
    fn method(&self) -> Method {
        Method::Path
    }

    fn pass(
        &self,
        scene: &Scene,
        camera: &CameraPass,
        progress: Mode,
        guide: &mut super::Guide,
        stats: &mut Stats,
    ) -> Film {
        let integrator = PathIntegrator { scene, shadow_rays: self.shadow_rays, skip: self.skip, mis: true };
        shoot(camera, &integrator, progress, guide, stats)
    }
}

/// The CS475 Whitted tracer: the course's n x n jittered grid per pixel,
/// no rim samples (its lights are points).
pub struct WhittedTracing {
    /// Bounce rays stop after this many reflections (0: none).
    pub max_depth: u32,
}

impl WhittedTracing {
    /// The course's default depth.
    pub const DEPTH: u32 = 5;
}

impl RenderMethod for WhittedTracing {
    fn method(&self) -> Method {
        Method::Whitted
    }

    fn pass(
        &self,
        scene: &Scene,
        camera: &CameraPass,
        progress: Mode,
        guide: &mut super::Guide,
        stats: &mut Stats,
    ) -> Film {
        let camera = CameraPass { placement: Placement::JitteredGrid, edge_spp: 0, ..*camera };
        let integrator = Whitted { scene, max_depth: self.max_depth };
        shoot(&camera, &integrator, progress, guide, stats)
    }
}
