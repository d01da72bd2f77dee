//! `photonmap export --mitsuba [SCENE.toml] OUT.xml`: the flags of
//! `photonmap::command::export`.

use photonmap::command::export::{self, Request};
use photonmap::command::values::parse_point;
use photonmap::error::Error;
use std::path::PathBuf;

/// Writes the scene (a scene file, or the built-in room) as a Mitsuba 3
/// scene: OUT.xml and its meshes in OUT-meshes/. What Mitsuba has no
/// faithful equivalent for is refused, with its place in the file.
#[derive(clap::Args, Debug)]
#[command(after_help = "Example: photonmap export --mitsuba scenes/suite/02-cornell.toml cornell.xml\n\
                        Render it: python3 -c \"import mitsuba as mi; mi.set_variant('scalar_rgb'); \
                        mi.Bitmap(mi.render(mi.load_file('cornell.xml', spp=64))).write('cornell.exr')\"")]
pub struct Args {
    /// Write for Mitsuba 3 (the one format there is).
    #[arg(long, required = true)]
    mitsuba: bool,
    /// The scene file (omit it for the built-in room), then the XML to write.
    #[arg(value_name = "[SCENE.toml] OUT.xml", num_args = 1..=2, required = true)]
    paths: Vec<PathBuf>,
    /// Built-in room: eye 1 = (-2,0,0), 2 = (-1,0,0) [default: 1].
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=2))]
    eye: Option<u8>,
    /// The point of the scene written as Mitsuba's origin [default: the
    /// camera's eye]. Mitsuba offsets a ray leaving a surface by a length
    /// that grows with the distance from its origin: for a reference that
    /// resolves a small glass object or a sharp shadow, give its centre
    /// here.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point, allow_hyphen_values = true)]
    origin: Option<glam::Vec3>,
    /// Mitsuba's units per scene unit (the image is the same); with
    /// --origin, a large scale makes the ray offsets a fixed fraction of
    /// the distance from the origin.
    #[arg(long, default_value_t = 1.0)]
    scale: f32,
}

pub fn run(args: Args) -> Result<(), Error> {
    export::run(Request { paths: args.paths, eye: args.eye, origin: args.origin, scale: args.scale })
}
