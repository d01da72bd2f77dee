//! Rendering: a render method ([`method`]: photon mapping, path tracing,
//! the Whitted tracer) renders passes (a photon stage where it has one,
//! then the camera pass); a classic render is one pass, a progressive
//! render averages passes whose estimates narrow; the driver ([`driver`])
//! runs either within a budget, reporting each pass to observers.

pub mod adaptive;
pub mod camera_pass;
pub mod driver;
pub mod error_estimate;
pub mod media_stage;
pub mod method;
pub mod photon_stage;
mod rims;
pub mod settings;
pub mod tracers;

pub use adaptive::{Guide, Samples};
pub use camera_pass::{camera_pass, CameraPass, Placement};
pub use driver::{drive, render_passes, render_progressive, Budget, Observer, PassReport, Plan, Run, Stopped};
pub use method::{Method, RenderMethod};
pub use photon_stage::GLOBAL_GRID_CELL;
pub use rims::Rims;

use crate::film::Film;
use crate::progress::Mode;
use crate::render::settings::Settings;
use crate::scene::Scene;
use crate::stats::Stats;

/// Renders `scene` (its camera at `settings`' resolution) in one pass.
pub fn render(scene: &Scene, settings: &Settings, progress: Mode) -> (Film, Stats) {
    render_with(scene, settings, settings.method.unit(settings).as_ref(), progress)
}

/// Renders `scene` in one pass of `method` (a unit made otherwise than
/// from `settings`: the Whitted tracer's depth).
pub fn render_with(scene: &Scene, settings: &Settings, method: &dyn RenderMethod, progress: Mode) -> (Film, Stats) {
    render_pass(scene, settings, method, 0, progress, &mut Guide::default())
}

/// Pass `pass` of a render: its own photons and camera samples, and (for
/// photon mapping) the estimates of
/// [`photon_stage::Estimates::progressive`], which for pass 0 are the
/// classic ones. A one-pass render is pass 0. `guide`: the pixels on the
/// rim of a light's image and the camera samples' counts, found by the
/// first pass that needs them and kept for the passes after it (see
/// [`camera_pass`]).
pub(crate) fn render_pass(
    scene: &Scene,
    settings: &Settings,
    method: &dyn RenderMethod,
    pass: u32,
    progress: Mode,
    guide: &mut Guide,
) -> (Film, Stats) {
    let mut stats = Stats { passes: 1, ..Stats::default() };
    let camera = CameraPass {
        camera: scene.camera.with_resolution(settings.width, settings.height),
        spp: settings.spp,
        edge_spp: settings.edge_spp,
        seed: settings.seed,
        pass: pass as u64,
        placement: Placement::Sobol,
    };
    let film = method.pass(scene, &camera, progress, guide, &mut stats);
    (film, stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Eye;
    use photon_stage::{photon_integrator, photon_pass, Estimates};

    /// The rim pixels are found by the first pass and used as they are by
    /// the passes after it (their probes are not cast again).
    #[test]
    fn later_passes_take_the_rims_they_are_given() {
        let scene = Scene::tncg15(Eye::One);
        let settings =
            Settings { photons: 5_000, caustic_photons: 5_000, width: 48, height: 48, spp: 1, ..Settings::default() };
        let mut guide = Guide::default();
        let unit = settings.method.unit(&settings);
        let pass = |pass, guide: &mut Guide| render_pass(&scene, &settings, unit.as_ref(), pass, Mode::Quiet, guide);
        let (_, first) = pass(0, &mut guide);
        let found = guide.rims.clone().expect("the first pass fills the rims");
        assert_eq!(first.edge_pixels, found.count());
        assert!(first.edge_pixels > 0 && first.edge_pixels < 48 * 48 / 4, "{} rim pixels", first.edge_pixels);
        let (_, second) = pass(1, &mut guide);
        assert_eq!(guide.rims.as_ref(), Some(&found));
        assert_eq!(second.edge_pixels, first.edge_pixels);
        // The rims share the pass's other samples (48 x 48 at 1 spp): each
        // takes that share on average, to a sample's rounding.
        let even = settings.edge_spp.min((48 * 48 / first.edge_pixels) as u32);
        assert!((even - 1..=even).contains(&second.edge_spp), "{} of {even}", second.edge_spp);
        // Every pixel given as a rim takes the split estimate: a primary ray
        // more for its emitted part, one sample, as the rims may take no
        // more samples than the pass's others.
        let with = |rims| Guide { rims: Some(rims), ..Guide::default() };
        let (_, none) = pass(1, &mut with(Rims::none(48 * 48)));
        let (_, all) = pass(1, &mut with(Rims::from_spread(vec![1.0; 48 * 48])));
        assert_eq!((none.edge_pixels, all.edge_pixels), (0, 48 * 48));
        assert_eq!(all.edge_spp, 1);
        assert!(all.camera.rays >= none.camera.rays + 48 * 48, "{} {}", all.camera.rays, none.camera.rays);
    }

    /// In a room lined with mirrors the light's images fill most of the
    /// view and each probe of the emitted part follows the mirrors to the
    /// depth limit, costing more than a whole sample: no pixel is taken for
    /// a rim there (before, most were, at twice a pass's cost). The plain
    /// room keeps its rim.
    #[test]
    fn a_mirror_lined_room_has_no_rims() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/tncg15.toml")).unwrap();
        let walls = "floor = \"grey\"\nceiling = \"grey\"\nwalls = [\"magenta\", \"red\", \"yellow\", \"blue\", \"green\", \"cyan\"]";
        assert!(text.contains(walls));
        let mirrors = format!("floor = \"mirror\"\nceiling = \"mirror\"\nwalls = [{}]", ["\"mirror\""; 6].join(", "));
        let settings =
            Settings { photons: 5_000, caustic_photons: 5_000, width: 64, height: 64, spp: 4, ..Settings::default() };
        let unit = settings.method.unit(&settings);
        let rims = |text: &str| {
            let file = crate::scene::file::parse(text, std::path::Path::new("room.toml")).unwrap();
            let scene = Scene::from_parts(file.parts);
            let stats = render_pass(&scene, &settings, unit.as_ref(), 0, Mode::Quiet, &mut Guide::default()).1;
            (stats.edge_pixels, stats.camera.rims_too_costly)
        };
        let (plain, mirrored) = (rims(&text), rims(&text.replace(walls, &mirrors)));
        assert!(plain.0 > 0 && plain.1 == 0, "{plain:?}");
        // The summary says why the mirrored room has none.
        assert_eq!(mirrored, (0, 1));
    }

    /// Cache reads left for the end of a pixel and resolved together give
    /// what reads made at once give, to rounding: the weights they carry
    /// follow the camera path through glass (both branches at the first
    /// vertices, Fresnel's choice deeper) and mirrors. (The radiance scale
    /// of refraction cancels on the way in and out of the sphere, so this
    /// scene cannot tell whether it is carried.)
    #[test]
    fn deferred_reads_resolve_to_the_reads_made_at_once() {
        use crate::integrator::{Context, Integrator};
        use crate::sampling::{stream, Domain};
        use crate::stats::Counters;
        let scene = Scene::tncg15(Eye::One);
        let settings = Settings { photons: 20_000, width: 48, height: 48, ..Settings::default() };
        let est = Estimates::progressive(&scene, &settings, 0);
        let maps = photon_pass(&scene, &settings, 0, est, Mode::Quiet, &mut Stats::default());
        let deferred = photon_integrator(&scene, &settings, &maps, est);
        let mut at_once = photon_integrator(&scene, &settings, &maps, est);
        at_once.settings.defer_reads = false;
        let camera = scene.camera.with_resolution(48, 48);
        let mut counters = Counters::default();
        let (mut thread, mut reads) = (Default::default(), 0);
        for pixel in 0..48 * 48u64 {
            let ray = camera.ray(pixel as u32 % 48, pixel as u32 / 48, glam::Vec2::splat(0.5));
            // At once, then deferred.
            let mut out = [(glam::Vec3::ZERO, glam::Vec3::ZERO); 2];
            for (integrator, out) in [&at_once, &deferred].into_iter().zip(&mut out) {
                let mut rng = stream(3, Domain::Camera, pixel);
                let mut ctx = Context { rng: &mut rng, counters: &mut counters, pixel };
                let mut state = Default::default();
                let radiance =
                    integrator.radiance(ray, crate::integrator::Part::All, &mut ctx, &mut thread, &mut state);
                let left = integrator.finish(&mut ctx, &mut thread, &mut state);
                *out = (radiance, left);
            }
            let [(a, none_left), (b, left)] = out;
            assert_eq!(none_left, glam::Vec3::ZERO);
            reads += (left != glam::Vec3::ZERO) as u32;
            let resolved = b + left;
            for c in 0..3 {
                let (x, y) = (a[c], resolved[c]);
                assert!((x - y).abs() <= 1e-5 * x.abs().max(1e-3), "pixel {pixel}: {a} at once, {resolved} deferred");
            }
        }
        assert!(reads > 48 * 48 / 2, "{reads} pixels left reads");
    }
}
