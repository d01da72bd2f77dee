//! Light must not leak through a surface into what it closes (issue 44,
//! item 8): photon-map estimates and the irradiance cache read photons
//! within a radius, and the far side of a small closed object lies within
//! it.

mod common;
use common::{photonmap, scratch_dir};

/// The default room with a grey sphere of radius 1 around the eye: the
/// camera sees only the sphere's inside, which no light reaches. The path
/// tracer renders it black; photon mapping read the sphere's outside
/// through it (mean 0.018 at 2e4 photons, whose radius cap exceeds the
/// sphere) and must now render it black too.
#[test]
fn the_inside_of_a_closed_sphere_around_the_camera_stays_black() {
    let dir = scratch_dir("leaks-sphere");
    let room = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/tncg15.toml")).unwrap();
    let sphere = "\n[[shapes]]\ntype = \"sphere\"\ncenter = [-1.2, 0.0, 0.0]\nradius = 1.0\nmaterial = \"grey\"\n";
    let scene = dir.join("inside.toml");
    std::fs::write(&scene, room + sphere).unwrap();
    for (integrator, photons) in [("photon", "2e4"), ("photon", "1e5"), ("photon", "2e5"), ("path", "")] {
        let out = dir.join(format!("{integrator}-{photons}.exr"));
        let mut args = vec!["--scene", scene.to_str().unwrap(), "--integrator", integrator, "--width", "16"];
        args.extend(["--height", "16", "--quiet", out.to_str().unwrap()]);
        if !photons.is_empty() {
            args.extend(["--photons", photons]);
        }
        let o = photonmap(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let film = photonmap::output::read_exr(&out).unwrap();
        let max = film.pixels.iter().map(|c| c.max_element()).fold(0.0f32, f32::max);
        assert!(max < 1e-6, "{integrator}, {photons} photons: brightest {max}, mean {}", film.mean());
    }
}
