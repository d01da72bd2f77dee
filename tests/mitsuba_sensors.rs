//! Mitsuba 3's `orthographic` and `thinlens` sensors on small scenes
//! written here: the orthographic view's extent is its `to_world` scale,
//! pixel for pixel; a thin lens keeps the plane in focus sharp and blurs a
//! point off it into the disc the thin-lens formula gives, without changing
//! the light the image collects; a lens of radius 0 is the perspective
//! camera; every bad value is refused at its place.

mod common;

use common::{render_quiet, scratch_dir};
use photonmap::film::Film;
use photonmap::scene::mitsuba::{load, Options};
use photonmap::scene::Scene;
use photonmap::settings::{Method, Settings};
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn read(path: &Path) -> Result<Scene, String> {
    let imported = load(path, &Options::default()).map_err(|e| e.to_string())?;
    Ok(Scene::from_parts(imported.file.parts))
}

/// The scene by path tracing (the camera sees only emitters here: every
/// sample is exactly their radiance or zero).
fn render(scene: &Scene, spp: u32) -> Film {
    render_by(Method::Path, scene, spp)
}

fn render_by(method: Method, scene: &Scene, spp: u32) -> Film {
    let settings = Settings {
        method,
        photons: 10_000,
        caustic_photons: 0,
        spp,
        width: scene.camera.width,
        height: scene.camera.height,
        ..Settings::default()
    };
    render_quiet(scene, &settings)
}

/// A rectangle emitting radiance 1 towards -z (Mitsuba's rectangle faces
/// +z), half-sizes `hx`, `hy`, centred at (x, y, z).
fn glowing_rectangle(hx: f64, hy: f64, x: f64, y: f64, z: f64) -> String {
    format!(
        r#"<shape type="rectangle"><transform name="to_world"><scale x="{hx}" y="{hy}"/><rotate y="1" angle="180"/>
        <translate x="{x}" y="{y}" z="{z}"/></transform><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>"#
    )
}

/// An orthographic sensor at the origin looking along +z, its frame scaled
/// by 2: the 40x20 film spans x in [-2, 2] (+x at the image's left) and y
/// in [-1, 1] (the height is the width over the aspect ratio). A rectangle
/// a hundredth of a pixel short of pixel edges on every side lights
/// exactly the pixels whose centres the scale puts in it, and those (bar
/// the edges' strips) completely; a crop window of those pixels is all
/// lit.
#[test]
fn an_orthographic_view_spans_its_scale() {
    let dir = scratch_dir("mitsuba_orthographic");
    let (hx, hy, cx, cy) = (0.5 - 0.001, 0.3 - 0.001, 1.0, 0.2);
    let text = |crop: &str| {
        format!(
            r#"<scene version="3.0.0"><sensor type="orthographic">
  <transform name="to_world"><scale x="2" y="2"/></transform>
  <film type="hdrfilm"><integer name="width" value="40"/><integer name="height" value="20"/>{crop}<rfilter type="box"/></film>
  <sampler type="independent"><integer name="sample_count" value="4"/></sampler></sensor>
  {}</scene>"#,
            glowing_rectangle(hx, hy, cx, cy, 5.0)
        )
    };
    let scene = read(&write(&dir, "o.xml", &text(""))).unwrap();
    let film = render(&scene, 4);
    // Photon mapping's camera pass takes the same rays.
    assert_eq!(render_by(Method::Photon, &scene, 4), film);
    let mut lit = 0;
    for row in 0..20 {
        for col in 0..40 {
            // Mitsuba's orthographic_projection inverted: the film's
            // [0, 1]^2 to x = 1 - 2 sx, y = (1 - 2 sy) / aspect, then scaled.
            let x = 2.0 * (1.0 - 2.0 * (col as f64 + 0.5) / 40.0);
            let y = 2.0 * (1.0 - 2.0 * (row as f64 + 0.5) / 20.0) / 2.0;
            let inside = (x - cx).abs() < hx && (y - cy).abs() < hy;
            let v = film.get(col, row).x;
            if inside {
                lit += 1;
                assert!(v > 0.5, "({col}, {row}) should be lit: {v}");
            } else {
                assert_eq!(v, 0.0, "({col}, {row}) should be dark");
            }
        }
    }
    // Columns 5..15 (x from 1.5 down to 0.5), rows 5..11 (y from 0.5 down
    // to -0.1).
    assert_eq!(lit, 10 * 6);
    assert_eq!(film.get(7, 7).x, 1.0, "a pixel well inside is the radiance exactly");
    let crop = r#"<integer name="crop_offset_x" value="5"/><integer name="crop_offset_y" value="5"/>
        <integer name="crop_width" value="10"/><integer name="crop_height" value="6"/>"#;
    let cropped = render(&read(&write(&dir, "c.xml", &text(crop))).unwrap(), 4);
    assert_eq!((cropped.width, cropped.height), (10, 6));
    assert!(cropped.pixels.iter().all(|p| p.x > 0.5), "the crop window is the lit rectangle");
}

/// A thin-lens (or, with radius 0, perspective) sensor at the origin
/// looking along +z: 64x64, 40° across.
fn lens_sensor(kind: &str, radius: f64, focus: f64) -> String {
    let lens = match kind {
        "thinlens" => {
            format!(r#"<float name="aperture_radius" value="{radius}"/><float name="focus_distance" value="{focus}"/>"#)
        }
        _ => String::new(),
    };
    format!(
        r#"<sensor type="{kind}"><float name="fov" value="40"/>{lens}
  <transform name="to_world"><lookat origin="0,0,0" target="0,0,1" up="0,1,0"/></transform>
  <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="64"/><rfilter type="box"/></film></sensor>"#
    )
}

/// A disk of radius `rho` at depth `z` on the axis, emitting radiance 1
/// towards the camera.
fn glowing_disk(rho: f64, z: f64) -> String {
    format!(
        r#"<shape type="disk"><transform name="to_world"><scale value="{rho}"/><rotate y="1" angle="180"/>
        <translate z="{z}"/></transform><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>"#
    )
}

/// The image's total, and the variance per axis (in pixels squared) of
/// where its light falls, about its centroid; and the centroid's distance
/// from the image's centre.
fn spread(film: &Film) -> (f64, f64, f64) {
    let (mut sum, mut mx, mut my) = (0.0, 0.0, 0.0);
    for row in 0..film.height {
        for col in 0..film.width {
            let v = film.get(col, row).x as f64;
            sum += v;
            mx += v * (col as f64 + 0.5);
            my += v * (row as f64 + 0.5);
        }
    }
    let (mx, my) = (mx / sum, my / sum);
    let mut var = 0.0;
    for row in 0..film.height {
        for col in 0..film.width {
            let v = film.get(col, row).x as f64;
            var += v * ((col as f64 + 0.5 - mx).powi(2) + (row as f64 + 0.5 - my).powi(2));
        }
    }
    let off = ((mx - film.width as f64 / 2.0).powi(2) + (my - film.height as f64 / 2.0).powi(2)).sqrt();
    (sum, var / sum / 2.0, off)
}

/// A thin lens of radius A focused at f images a point at depth z as a
/// disc of radius A |1/z - 1/f| on the image plane at distance 1 (the lens
/// point L sends the ray for image point x through f x, meeting depth z at
/// L (1 - z/f) + z x). A small glowing disk (radius rho) is a point blurred
/// by its own image, radius rho / z: uniform discs add their variances
/// R^2 / 4 per axis, and a pixel's box adds about 1/12 (Sheppard's
/// correction; 3% short for the pinhole's 1.8-pixel image here). In the plane in focus the
/// lens changes nothing; off it, it blurs without changing the total.
#[test]
fn a_thin_lens_blurs_what_is_out_of_focus_by_the_thin_lens_formula() {
    let dir = scratch_dir("mitsuba_thinlens");
    // The disk subtends the same angle at every depth: radius 0.02 z.
    let (radius, focus) = (0.2, 2.0);
    let pixel = 2.0 * 20f64.to_radians().tan() / 64.0;
    let image = |kind: &str, z: f64| {
        let text = format!(
            "<scene version=\"3.0.0\">{}{}</scene>",
            lens_sensor(kind, radius, focus),
            glowing_disk(0.02 * z, z)
        );
        render(&read(&write(&dir, "l.xml", &text)).unwrap(), 1024)
    };
    let own = (0.02 / pixel).powi(2) / 4.0 + 1.0 / 12.0;
    for z in [1.0, 2.0, 4.0] {
        let (pin_sum, pin_var, pin_off) = spread(&image("perspective", z));
        let (sum, var, off) = spread(&image("thinlens", z));
        let blur = radius * (1.0 / z - 1.0 / focus).abs() / pixel;
        let want = blur * blur / 4.0 + own;
        eprintln!("z {z}: variance {var:.3} px^2 (formula {want:.3}), pinhole {pin_var:.3} ({:.3}); total {sum:.2} vs {pin_sum:.2}", own);
        assert!(
            (var / want - 1.0).abs() < 0.05,
            "z {z}: variance {var} px^2, the formula {want} (blur radius {blur} px)"
        );
        assert!((pin_var / own - 1.0).abs() < 0.05, "z {z}: pinhole variance {pin_var}, want {}", own);
        assert!((sum / pin_sum - 1.0).abs() < 0.02, "z {z}: the lens collects {sum}, the pinhole {pin_sum}");
        // About 10,000 samples see the disk: the centroid's noise is
        // 0.03 px or less.
        assert!(off < 0.1 && pin_off < 0.1, "z {z}: centred ({off}, {pin_off})");
        if z == focus {
            assert!((var / pin_var - 1.0).abs() < 0.05, "in focus it stays sharp: {var} vs {pin_var}");
        } else {
            assert!(var > 2.0 * pin_var, "z {z}: blurred");
        }
    }
}

/// A lens of radius 0 is Mitsuba's pinhole: the same rays and, sample for
/// sample, the same image as the perspective sensor.
#[test]
fn a_thin_lens_of_radius_zero_is_the_perspective_camera() {
    let dir = scratch_dir("mitsuba_thinlens_zero");
    let body = format!("{}{}", glowing_disk(0.3, 3.0), glowing_rectangle(0.5, 0.2, 0.4, -0.3, 5.0));
    let scene = |sensor: String| {
        read(&write(&dir, "z.xml", &format!("<scene version=\"3.0.0\">{sensor}{body}</scene>"))).unwrap()
    };
    let (thin, perspective) = (scene(lens_sensor("thinlens", 0.0, 2.0)), scene(lens_sensor("perspective", 0.0, 0.0)));
    assert!(!thin.camera.projection.has_lens());
    for (col, row) in [(0, 0), (17, 40), (63, 63)] {
        let u = glam::Vec2::new(0.3, 0.8);
        let (a, b) = (thin.camera.ray(col, row, u), perspective.camera.ray(col, row, u));
        assert_eq!((a.origin, a.dir), (b.origin, b.dir));
    }
    assert_eq!(render(&thin, 4), render(&perspective, 4));
}

/// Every bad value of the two sensors is refused at its file, line and
/// column.
#[test]
fn bad_sensor_values_are_refused_at_their_place() {
    let dir = scratch_dir("mitsuba_sensor_refusals");
    let film = r#"<film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>"#;
    let cases: [(&str, &str, &str); 8] = [
        ("no aperture", r#"<sensor type="thinlens">"#, ":2:1: sensor 'thinlens': the thinlens sensor needs aperture_radius"),
        (
            "negative aperture",
            r#"<sensor type="thinlens">
<float name="aperture_radius" value="-0.1"/>"#,
            ":3:1: sensor 'thinlens'.aperture_radius: must be in [0, 1e15], got -0.1",
        ),
        (
            "focus behind the lens",
            r#"<sensor type="thinlens"><float name="aperture_radius" value="0.1"/>
<float name="focus_distance" value="0"/>"#,
            ":3:1: sensor 'thinlens'.focus_distance: must be in (0, 1e15]",
        ),
        (
            "a principal point on a thin lens",
            r#"<sensor type="thinlens"><float name="aperture_radius" value="0.1"/>
<float name="principal_point_offset_x" value="0.1"/>"#,
            ":3:1: sensor 'thinlens': 'principal_point_offset_x' is not supported",
        ),
        (
            "scale on a thin lens",
            r#"<sensor type="thinlens"><float name="aperture_radius" value="0.1"/>
<transform name="to_world"><scale value="2"/></transform>"#,
            ":3:1: sensor 'thinlens'.to_world: scale factors",
        ),
        (
            "a flat orthographic view",
            r#"<sensor type="orthographic">
<transform name="to_world"><scale x="2" y="2" z="0"/></transform>"#,
            ":3:1: sensor 'orthographic'.to_world: the transform flattens the view",
        ),
        (
            "far before near",
            r#"<sensor type="orthographic"><float name="near_clip" value="2"/>
<float name="far_clip" value="1"/>"#,
            ":3:1: sensor 'orthographic'.far_clip: must exceed near_clip (2), got 1",
        ),
        (
            "an unknown sensor",
            r#"<sensor type="radiancemeter">"#,
            ":2:1: sensor 'radiancemeter': the 'radiancemeter' sensor is not supported (perspective, thinlens and orthographic are)",
        ),
    ];
    for (what, open, want) in cases {
        let text = format!("<scene version=\"3.0.0\">\n{open}{film}</sensor>\n{}</scene>", glowing_disk(0.1, 3.0));
        let e = read(&write(&dir, "s.xml", &text)).err().unwrap_or_else(|| panic!("{what}: read"));
        assert!(e.contains("s.xml") && e.contains(want), "{what}: {e}");
    }
}

/// The export writes a thin lens as `thinlens` and an orthographic camera
/// as `orthographic`; read back, each gives the rays it was written from
/// (up to the near clip the export adds, which moves an origin along its
/// ray).
#[test]
fn exported_sensors_read_back_as_the_same_camera() {
    use glam::{Vec2, Vec3};
    use photonmap::camera::Projection;
    use photonmap::export::mitsuba::{to_mitsuba, Placement};
    let dir = scratch_dir("mitsuba_sensor_export");
    let room = photonmap::scene::Scene::tncg15_parts(photonmap::scene::Eye::One);
    let axis = room.camera.axis();
    for projection in [Projection::ThinLens { radius: 0.1, focus: 5.0 }, Projection::Orthographic { dir: axis }] {
        let mut parts = photonmap::scene::Scene::tncg15_parts(photonmap::scene::Eye::One);
        parts.camera.projection = projection;
        let written = to_mitsuba(&parts, None, "m", Placement::new(Vec3::ZERO, 1.0).unwrap())
            .unwrap_or_else(|r| panic!("{}", r.describe(None)));
        std::fs::create_dir_all(dir.join("m")).unwrap();
        for (name, bytes) in &written.meshes {
            std::fs::write(dir.join(name), bytes).unwrap();
        }
        let back = read(&write(&dir, "e.xml", &written.xml)).unwrap().camera;
        assert_eq!(back.projection.has_lens(), projection.has_lens(), "{}", written.xml);
        assert_eq!((back.width, back.height), (parts.camera.width, parts.camera.height));
        for (col, row, u, lens) in [(0, 0, 0.1, 0.9), (400, 123, 0.5, 0.2), (799, 799, 0.9, 0.6)] {
            let (u, lens) = (Vec2::new(u, 1.0 - u), Vec2::new(lens, 0.3));
            let a = parts.camera.sample_ray(col, row, u, lens);
            let b = back.sample_ray(col, row, u, lens);
            let off_line = (b.origin - a.origin) - (b.origin - a.origin).dot(a.dir) * a.dir;
            assert!((a.dir - b.dir).length() < 1e-5 && off_line.length() < 1e-5, "{projection:?}: {a:?} vs {b:?}");
        }
    }
}
