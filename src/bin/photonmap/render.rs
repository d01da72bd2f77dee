//! Rendering: the default command's flags, made into a request for
//! `photonmap::command::render`.

use crate::args::*;
use crate::count::{count, parse_seed};
use photonmap::command::checks::use_threads;
use photonmap::command::outputs::{Look, Outputs};
use photonmap::command::render::{self, Outcome, Request};
use photonmap::error::Error;
use photonmap::film::ToneMap;
use photonmap::render::Method;
use photonmap::scene::Eye;
use photonmap::settings::{Settings, DEFAULT};
use std::path::PathBuf;

/// Outputs of a progressive render are rewritten this often, so a run
/// that dies keeps an image (and a partial) of its passes so far.
const REWRITE_SECONDS: f64 = 10.0;

/// Rendering (the default command).
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// Render this scene file instead of the built-in room: photonmap's TOML
    /// (notes/scene-format.md) or Mitsuba 3's XML (.xml, notes/mitsuba.md);
    /// its camera, resolution and samples per pixel are the defaults of
    /// --width, --height and --spp.
    #[arg(long, value_name = "SCENE.toml|SCENE.xml", conflicts_with = "eye")]
    scene: Option<PathBuf>,
    /// Set a Mitsuba scene's parameter $NAME, as Mitsuba's -D does
    /// (repeatable; wins over the file's <default>).
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define, requires = "scene")]
    defines: Vec<(String, String)>,
    /// Render a Mitsuba scene even where a BSDF or emitter is not supported:
    /// a grey diffuse BSDF stands in, an emitter is left out; each is listed
    /// on stderr and in the EXR's header.
    #[arg(long, requires = "scene")]
    substitute: bool,
    /// Output images; the extension picks the format: .exr (linear float
    /// radiance, with how it was made in its header, and for progressive
    /// renders the error estimate's layers), .png or .ppm (8-bit,
    /// tone-mapped).
    #[arg(value_name = "OUT")]
    outputs: Vec<PathBuf>,
    /// More output images (repeatable), as for OUT.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    more_outputs: Vec<PathBuf>,
    /// Estimator: photon (photon mapping) or path (path tracing with
    /// next-event estimation, unbiased: the reference). Default: photon;
    /// path for a Mitsuba scene whose integrator stops paths at 3 or more
    /// vertices (max_depth), which photon mapping cannot do, and for a
    /// scene with participating media (photon: volumetric photon mapping).
    #[arg(long, value_enum)]
    integrator: Option<Named<Method>>,
    /// Progressive rendering: passes 0 to N-1, averaged (with --resume:
    /// until the image holds N passes). Photon mapping narrows its
    /// estimates from pass to pass so the image converges to the true one.
    #[arg(long, value_parser = count(1, 10_000_000))]
    passes: Option<u32>,
    /// Progressive rendering for this many seconds (no pass starts that
    /// would end later; at least one runs). Outputs are rewritten every 10
    /// s, so stopping early keeps a valid image. With --passes or
    /// --target-error, a cap.
    #[arg(long, value_parser = parse_seconds)]
    time: Option<f64>,
    /// Progressive rendering until the predicted relative RMSE (of every
    /// --window, or of the whole image) is below this (0.02: 2%); checked
    /// from the fourth pass on. --time caps it, else a week (a prediction
    /// beyond the cap is said).
    #[arg(long, value_name = "E", value_parser = parse_target)]
    target_error: Option<f64>,
    /// A rectangle of pixels whose predicted error is reported (and, with
    /// --target-error, aimed at), as [NAME=]ROW0:ROW1,COL0:COL1 (half-open,
    /// row 0 at the top); repeatable.
    #[arg(long = "window", value_name = "[NAME=]R0:R1,C0:C1")]
    windows: Vec<String>,
    /// Render only passes A to B-1 of a progressive render ("A..B"; "A.."
    /// with --time or --target-error) and write them as a partial render
    /// (--partial), for `photonmap merge`.
    #[arg(long, value_name = "A..B", requires = "partial")]
    pass_range: Option<String>,
    /// Also write the progressive render's exact sums and a manifest to
    /// this EXR (a partial render): what `merge` adds and `--resume` goes
    /// on from. Rewritten with the outputs, and written on Ctrl-C.
    #[arg(long, value_name = "PART.exr")]
    partial: Option<PathBuf>,
    /// Go on with the progressive render in this partial (same scene and
    /// settings), from the pass after its last, until --passes (counting the
    /// passes in the image), --time (this run's seconds) or --target-error:
    /// one is needed. --partial may name the same file: it is replaced,
    /// atomically, by the longer render.
    #[arg(long, value_name = "PART.exr", conflicts_with = "pass_range")]
    resume: Option<PathBuf>,
    /// Write a heat map of the per-pixel predicted error (progressive).
    #[arg(long, value_name = "FILE.png")]
    error_map: Option<PathBuf>,
    /// Show each progressive pass in the tev image viewer listening at
    /// HOST:PORT (tev's default: 127.0.0.1:14158).
    #[arg(long, value_name = "HOST:PORT")]
    display: Option<String>,
    /// How fast progressive photon mapping narrows its estimates (Knaus &
    /// Zwicker's alpha): pass i uses k and squared radius caps times
    /// prod_{j<i} (j + alpha - 1) / j.
    #[arg(long, default_value_t = DEFAULT.alpha, value_parser = parse_alpha)]
    alpha: f32,
    /// Photons emitted for the global map, per pass (1e6, 2.5e5 and 1000000
    /// all work) [default: 1e6; 2.5e5 for progressive renders].
    #[arg(long, value_parser = parse_count)]
    photons: Option<u64>,
    /// Photons emitted towards mirrors and glass [default: as --photons;
    /// 1e6 for progressive renders given neither].
    #[arg(long, value_parser = parse_count)]
    caustic_photons: Option<u64>,
    /// Camera samples per pixel (a scrambled Sobol sequence, continued
    /// from pass to pass)
    /// [default: 4, or rays_per_pixel_edge squared from a scene file; 1 for
    /// progressive renders].
    #[arg(long, value_parser = count(1, 1_000_000))]
    spp: Option<u32>,
    /// Seed of every random stream: the same image on any number of threads.
    #[arg(long, default_value_t = DEFAULT.seed, value_parser = parse_seed)]
    seed: u64,
    /// Eye position of the built-in room: 1 = (-2,0,0), 53 degree view;
    /// 2 = (-1,0,0), 90 degrees [default: 1].
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=2))]
    eye: Option<u8>,
    /// Worker threads [default: all cores].
    #[arg(long, value_parser = count(1, 4096))]
    threads: Option<u32>,
    /// Image width in pixels [default: 800, or the scene file's]. A size of
    /// another shape than the camera's widens a look-at camera's view; a
    /// four-corner camera's plane must have the image's shape.
    #[arg(long, value_parser = count(1, 65_536))]
    width: Option<u32>,
    /// Image height in pixels [default: 800, or the scene file's].
    #[arg(long, value_parser = count(1, 65_536))]
    height: Option<u32>,
    /// Nearest photons per global-map irradiance estimate (at least 2: the
    /// estimate counts those strictly inside the k-th photon's distance).
    #[arg(long, default_value_t = DEFAULT.k_global as u32, value_parser = count(2, 100_000))]
    k: u32,
    /// Nearest photons per caustic estimate (at least 2) [default: 100; 400
    /// for progressive renders given no photon counts, whose passes take
    /// four times the caustic photons].
    #[arg(long, value_parser = count(2, 100_000))]
    k_caustic: Option<u32>,
    /// Largest search radius of a global-map estimate, in scene units
    /// [default: 5% of the scene's diagonal].
    #[arg(long, value_parser = parse_radius)]
    max_radius: Option<f32>,
    /// Largest search radius of a caustic estimate [default: 1% of the diagonal].
    #[arg(long, value_parser = parse_radius)]
    caustic_radius: Option<f32>,
    /// Final-gather rays per diffuse camera hit (0: no indirect light)
    /// [default: 4; 8 for photon mapping in a scene with media].
    #[arg(long, value_parser = count(0, 65_536))]
    gather_rays: Option<u32>,
    /// Of the gather rays, how many are aimed at the mirrors, glass and bright
    /// spots a point sees, if any; one at least stays cosine (0: all do).
    #[arg(long, default_value_t = DEFAULT.aimed_gather_rays, value_parser = count(0, 65_536))]
    aimed_gather_rays: u32,
    /// Shadow rays per light per diffuse camera hit [default: 2; 4 for
    /// photon mapping in a scene with media].
    #[arg(long, value_parser = count(1, 65_536))]
    shadow_rays: Option<u32>,
    /// Irradiance is precomputed at every N-th stored global photon, and
    /// final-gather rays read the nearest precomputed value [default: k / 6,
    /// 16 at k = 100, following k down in progressive passes].
    #[arg(long, value_parser = count(1, 65_536))]
    cache_stride: Option<u32>,
    /// A pixel's later camera samples reuse its last caustic estimate where
    /// they land on the same surface within this fraction of that
    /// estimate's radius (0 to 1; 0: every sample makes its own).
    #[arg(long, default_value_t = DEFAULT.caustic_reuse, value_parser = parse_fraction)]
    caustic_reuse: f32,
    /// Samples of the light seen in pixels on the rim of a light's image
    /// (directly or in mirrors and glass; 0: no extra samples).
    #[arg(long, default_value_t = DEFAULT.edge_spp, value_parser = count(0, 1_000_000))]
    edge_spp: u32,
    /// Do everything even where the scene cannot use it (photon maps, shadow
    /// rays towards lights facing away): for checking that the skips change
    /// nothing.
    #[arg(long)]
    no_skip: bool,
    /// Progressive renders: the passes after the first give more camera
    /// samples to the pixels whose samples disagreed in the first pass's
    /// pilot (by default every pixel takes the same samples).
    #[arg(long)]
    adaptive: bool,
    /// How 8-bit outputs (.png, .ppm) are made from radiance: display (an
    /// exposure from the image, then sRGB), or the course's linear (255.99 /
    /// i_max) and sqrt mappings, or clamp (1.0 is white). EXR is always
    /// linear radiance.
    #[arg(long, value_enum, default_value_t = Named(ToneMap::Display))]
    tonemap: Named<ToneMap>,
    /// Brightness factor of 8-bit outputs, applied on top of the tone map
    /// (values past white clip).
    #[arg(long, default_value_t = 1.0, value_parser = parse_exposure)]
    exposure: f32,
    /// Score the render against a reference EXR of the default scene (the
    /// metric of tools/metrics.py) and print the numbers.
    #[arg(long, value_name = "REF.exr")]
    reference: Option<PathBuf>,
    /// No progress bars and no summary.
    #[arg(short, long)]
    quiet: bool,
}

impl RenderArgs {
    /// The request these flags make.
    fn request(self) -> Result<Request, Error> {
        let windows = parse_windows(&self.windows).map_err(Error::Invalid)?;
        let outputs = Outputs {
            images: self.outputs.into_iter().chain(self.more_outputs).collect(),
            partial: self.partial,
            error_map: self.error_map,
        };
        let settings = Settings {
            alpha: self.alpha,
            seed: self.seed,
            k_global: self.k as usize,
            r_global: self.max_radius,
            r_caustic: self.caustic_radius,
            aimed_gather_rays: self.aimed_gather_rays,
            edge_spp: self.edge_spp,
            cache_stride: self.cache_stride.map(|n| n as usize),
            caustic_reuse: self.caustic_reuse,
            skip: !self.no_skip,
            adaptive: self.adaptive,
            ..DEFAULT
        };
        Ok(Request {
            scene: self.scene,
            eye: if self.eye == Some(2) { Eye::Two } else { Eye::One },
            defines: self.defines,
            substitute: self.substitute,
            outputs,
            method: self.integrator.map(|m| m.0),
            passes: self.passes,
            seconds: self.time,
            target_error: self.target_error,
            windows,
            pass_range: self.pass_range,
            resume: self.resume,
            photons: self.photons,
            caustic_photons: self.caustic_photons,
            k_caustic: self.k_caustic.map(|k| k as usize),
            gather_rays: self.gather_rays,
            shadow_rays: self.shadow_rays,
            spp: self.spp,
            width: self.width,
            height: self.height,
            settings,
            look: Look { tonemap: self.tonemap.0, exposure: self.exposure },
            reference: self.reference,
            quiet: self.quiet,
            display: self.display,
            rewrite_seconds: REWRITE_SECONDS,
        })
    }
}

/// Renders as the flags ask (the default command).
pub fn run(cli: RenderArgs) -> Result<Outcome, Error> {
    if let Some(threads) = cli.threads {
        use_threads(threads, !cli.quiet)?;
    }
    render::run(cli.request()?)
}
