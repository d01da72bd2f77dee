//! Scene files: every broken file in tests/scenes/bad/ is refused by both
//! programs with file:line:column, the field and what is wrong, a non-zero
//! exit and the existing output untouched; every file in scenes/ loads; the
//! default scene's file is the built-in room; mangled files never panic.

use photonmap::progress::Mode;
use photonmap::render::render;
use photonmap::scene::file::{load, parse};
use photonmap::scene::{Eye, Scene};
use photonmap::settings::Settings;
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// (file, line, column, field, part of the message)
const BROKEN: &[(&str, usize, usize, &str, &str)] = &[
    ("negative_radius.toml", 16, 10, "shapes[0].radius", "must be > 0 and at most 1e15, got -1.5"),
    ("unknown_field.toml", 16, 1, "shapes[0].radiu", "unknown field `radiu`"),
    ("wrong_type.toml", 16, 10, "shapes[0].radius", "invalid type: string \"large\""),
    ("missing_field.toml", 14, 8, "shapes[0].radius", "missing field `radius`"),
    ("unknown_material.toml", 17, 12, "shapes[0].material", "no material named \"chrome\""),
    ("missing_obj.toml", 15, 8, "shapes[0].file", "cannot open the OBJ file"),
    (
        "malformed_obj.toml",
        15,
        8,
        "shapes[0].file",
        "malformed.obj, line 3: vertex coordinate 2 is not a number: 'one'",
    ),
    ("obj_directory.toml", 16, 8, "shapes[0].file", "it is a directory"),
    ("obj_device.toml", 16, 8, "shapes[0].file", "/dev/zero: it is not a regular file"),
    ("duplicate_camera.toml", 19, 2, "camera", "duplicate key"),
    ("far_eye.toml", 3, 7, "camera.eye", "must be within ±1e15"),
    ("imprecise_eye.toml", 3, 7, "camera.eye", "too large for single precision to tell its pixels apart"),
    ("overflowing_color.toml", 17, 9, "lights[0].color", "must be within ±1e15"),
    ("far_emitter.toml", 16, 10, "lights[0].center", "must be within ±1e15"),
    ("overflowing_power.toml", 15, 8, "lights[0]", "emits 9.870e31 W"),
    ("syntax_error.toml", 16, 1, "shapes[0]", "missing comma"),
    ("unknown_light_type.toml", 14, 8, "lights[0].type", "unknown light type \"spot\""),
    ("zero_normal.toml", 16, 10, "lights[0].normal", "must not be the zero vector"),
    ("reflectance_over_one.toml", 15, 7, "materials.hot.rho", "at most 1"),
    ("zero_width.toml", 6, 9, "camera.width", "must be in [1, 65536], got 0"),
    ("negative_aperture.toml", 8, 19, "camera.aperture_radius", "must be >= 0 and at most 1e15, got -0.1"),
    ("lens_without_focus.toml", 9, 19, "camera.focus_distance", "a lens needs focus_distance"),
    ("two_vertices.toml", 15, 12, "shapes[0].vertices", "needs 3 vertices, got 2"),
    ("zero_radiance.toml", 20, 8, "lights[0]", "emits no light (a colour of 0"),
    ("tiny_disk_light.toml", 20, 8, "lights[0]", "nor does any other light, so the image would be black"),
];

#[test]
fn broken_scene_files_are_refused_with_their_place_and_nothing_is_written() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("broken-scenes");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("keep.png");
    for (name, line, column, field, message) in BROKEN {
        let path = root().join("tests/scenes/bad").join(name);
        let err = load(&path).expect_err(name);
        assert_eq!((err.line, err.column), (*line, *column), "{name}: {err}");
        assert!(err.field.starts_with(field), "{name}: field {} (want {field})", err.field);
        assert!(err.message.contains(message), "{name}: {}", err.message);
        for (program, args) in [
            (env!("CARGO_BIN_EXE_trace"), vec![path.to_str().unwrap(), out.to_str().unwrap()]),
            (
                env!("CARGO_BIN_EXE_photonmap"),
                vec!["--scene", path.to_str().unwrap(), "--photons", "100", "-q", out.to_str().unwrap()],
            ),
        ] {
            std::fs::write(&out, b"a good image").unwrap();
            let o = Command::new(program).args(&args).output().unwrap();
            let stderr = String::from_utf8_lossy(&o.stderr);
            assert!(!o.status.success(), "{program} accepted {name}");
            let place = format!("{name}:{line}:{column}: {field}");
            assert!(stderr.contains(&place) && stderr.contains(message), "{program} on {name}: {stderr}");
            assert_eq!(std::fs::read(&out).unwrap(), b"a good image", "{program} touched the output");
        }
    }
}

fn scene_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_scene_in_scenes_loads() {
    let files = scene_files();
    assert!(files.len() >= 6, "{files:?}");
    for f in files {
        let file = load(&f).unwrap_or_else(|e| panic!("{e}"));
        let scene = Scene::from_parts(file.parts);
        assert!(scene.prim_count() > 0 && !scene.lights.is_empty(), "{}", f.display());
    }
}

/// scenes/tncg15.toml is the built-in room: the same primitives in the same
/// order, so the same image bit for bit.
#[test]
fn the_default_scene_file_is_the_built_in_room() {
    let file = load(&root().join("scenes/tncg15.toml")).unwrap();
    assert_eq!(file.rays_per_pixel_edge * file.rays_per_pixel_edge, Settings::default().spp);
    assert!(file.not_physical.is_empty());
    let from_file = Scene::from_parts(file.parts);
    let built_in = Scene::tncg15(Eye::One);
    assert_eq!(from_file.prim_count(), built_in.prim_count());
    for prim in 0..built_in.prim_count() as u32 {
        assert_eq!(from_file.shape(prim), built_in.shape(prim));
        assert_eq!(from_file.material(prim), built_in.material(prim));
    }
    assert_eq!((from_file.camera.width, from_file.camera.height), (800, 800));
    let settings = Settings { photons: 20_000, caustic_photons: 20_000, width: 48, height: 48, ..Settings::default() };
    let (a, _) = render(&from_file, &settings, Mode::Quiet);
    let (b, _) = render(&built_in, &settings, Mode::Quiet);
    assert!(a.pixels == b.pixels, "the file's render differs from the built-in's");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]
    /// Mangled scene files (characters deleted, replaced or inserted, lines
    /// swapped) are either read or refused with a located error; never a panic.
    #[test]
    fn mangled_scene_files_never_panic(
        edits in prop::collection::vec((0usize..100_000, 0u8..4, any::<char>()), 1..6),
    ) {
        let text = std::fs::read_to_string(root().join("scenes/tncg15.toml")).unwrap();
        let mut chars: Vec<char> = text.chars().collect();
        for (at, kind, c) in edits {
            let i = at % chars.len().max(1);
            match kind {
                0 => { chars.remove(i); }
                1 => chars[i] = c,
                2 => chars.insert(i, c),
                _ => chars.insert(i, ['-', '0', '"', '[', ']', '=', '\n', 'e', '.'][at % 9]),
            }
        }
        let mangled: String = chars.into_iter().collect();
        match parse(&mangled, Path::new("mangled.toml")) {
            Ok(file) => { let _ = Scene::from_parts(file.parts); }
            Err(e) => prop_assert!(e.line >= 1 && !e.message.is_empty(), "{e}"),
        }
    }
}

/// photonmap refuses what it cannot honour (here the Whitted scenes'
/// ambient light), with the place in the file; `trace` renders the same
/// file, and its 8-bit output clamps (1.0 is 255).
#[test]
fn photonmap_refuses_whitted_only_features_that_trace_renders() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("whitted-only");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = root().join("scenes/whitted-spheres.toml");
    let out = dir.join("spheres.png");
    let _ = std::fs::remove_file(&out);
    let o = Command::new(env!("CARGO_BIN_EXE_photonmap"))
        .args(["--scene", scene.to_str().unwrap(), "-q", out.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.contains("whitted-spheres.toml:3:11: ambient:"), "{stderr}");
    assert!(!out.exists());
    let o = Command::new(env!("CARGO_BIN_EXE_trace"))
        .args([scene.to_str().unwrap(), out.to_str().unwrap(), "2"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (400, 300));
    // The sky is black, the floor lit, and nothing was normalised to the maximum.
    assert_eq!(img.get_pixel(200, 2).0, [0, 0, 0]);
    assert!(img.get_pixel(200, 290).0[0] > 60);
}

/// Photon mapping and the path tracer agree on scenes lit by an emissive
/// triangle and by point and directional lights (mean radiance within a few
/// percent: the two estimators share only the scene).
#[test]
fn photon_mapping_agrees_with_path_tracing_for_every_light_type() {
    let point_and_sun = r#"
        [camera]
        eye = [-2, 0, 0]
        target = [5, 0, -1]
        up = [0, 0, 1]
        vfov = 60
        width = 40
        height = 40
        [materials.white]
        type = "lambertian"
        rho = [0.7, 0.7, 0.7]
        [materials.glass]
        type = "glass"
        ior = 1.5
        [[shapes]]
        type = "room"
        floor = "white"
        ceiling = "white"
        walls = ["white", "white", "white", "white", "white", "white"]
        [[shapes]]
        type = "sphere"
        center = [8, 0, -3.5]
        radius = 1.5
        material = "glass"
        [[lights]]
        type = "point"
        position = [8, 0, 3]
        color = [20, 20, 20]
    "#;
    let sun = r#"
        [camera]
        eye = [0, -6, 5]
        target = [0, 0, 0]
        up = [0, 0, 1]
        vfov = 50
        width = 40
        height = 40
        [materials.white]
        type = "lambertian"
        rho = [0.7, 0.6, 0.5]
        [materials.glass]
        type = "glass"
        ior = 1.5
        [[shapes]]
        type = "disk"
        center = [0, 0, 0]
        normal = [0, 0, 1]
        radius = 6
        material = "white"
        [[shapes]]
        type = "sphere"
        center = [0, 0, 1.5]
        radius = 1
        material = "glass"
        [[lights]]
        type = "directional"
        direction = [0.3, 0.2, -1]
        color = [2, 2, 2]
    "#;
    let triangle = std::fs::read_to_string(root().join("scenes/tncg15-triangle-light.toml")).unwrap();
    for (name, text) in [
        ("point light", point_and_sun.to_string()),
        ("directional light", sun.to_string()),
        ("triangle light", triangle),
    ] {
        let mut parts = parse(&text, &root().join("scenes/x.toml")).unwrap().parts;
        parts.camera = parts.camera.with_resolution(40, 40);
        let scene = Scene::from_parts(parts);
        let base = Settings { width: 40, height: 40, ..Settings::default() };
        let photon = Settings { photons: 200_000, caustic_photons: 200_000, spp: 16, ..base };
        let path = Settings { method: photonmap::settings::Method::Path, spp: 1024, ..base };
        let (a, sa) = render(&scene, &photon, Mode::Quiet);
        let (b, _) = render(&scene, &path, Mode::Quiet);
        assert!(sa.global_stored > 0, "{name}: no photons stored");
        let (ma, mb) = (a.mean(), b.mean());
        assert!(mb > 0.0 && (ma - mb).abs() / mb < 0.05, "{name}: photon mean {ma} vs path {mb}");
    }
}

/// `trace` refuses an image whose film would not fit in memory, before
/// allocating it, instead of aborting half-way.
#[test]
fn trace_refuses_an_image_that_cannot_fit() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("trace-huge");
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(root().join("tests/scenes/bad/zero_width.toml"))
        .unwrap()
        .replace("width = 0\nheight = 16", "width = 65536\nheight = 65536");
    let scene = dir.join("huge.toml");
    std::fs::write(&scene, text).unwrap();
    let need = 65536u64 * 65536 * 16;
    if photonmap::memory::available_memory().is_none_or(|a| a >= need) {
        return; // a machine with 70 GB free would render it
    }
    let out = dir.join("huge.png");
    let o = Command::new(env!("CARGO_BIN_EXE_trace"))
        .args([scene.to_str().unwrap(), out.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.contains("65536 x 65536 image needs about"), "{stderr}");
    assert!(!out.exists());
}

/// `aperture_radius` puts a thin lens on the eye, focused at the target
/// in the look-at form unless `focus_distance` says otherwise; 0 is the
/// pinhole.
#[test]
fn a_camera_may_have_a_thin_lens() {
    use photonmap::camera::Projection;
    let text = |lens: &str| {
        format!(
            "[camera]\neye = [0, 0, 10]\ntarget = [0, 0, 4]\nup = [0, 1, 0]\nvfov = 40\nwidth = 16\nheight = 16\n{lens}\n\
             [[lights]]\ntype = \"point\"\nposition = [0, 0, 5]\ncolor = [1, 1, 1]\n"
        )
    };
    let projection = |lens: &str| parse(&text(lens), Path::new("lens.toml")).unwrap().parts.camera.projection;
    assert_eq!(projection(""), Projection::Pinhole);
    assert_eq!(projection("aperture_radius = 0"), Projection::Pinhole);
    assert_eq!(projection("aperture_radius = 0.25"), Projection::ThinLens { radius: 0.25, focus: 6.0 });
    assert_eq!(
        projection("aperture_radius = 0.25\nfocus_distance = 2.5"),
        Projection::ThinLens { radius: 0.25, focus: 2.5 }
    );
}
