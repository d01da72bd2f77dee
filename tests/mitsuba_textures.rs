//! Textures, masks, normal and bump maps and image-projecting lights of
//! the Mitsuba front-end, on small scenes written here, each against what
//! Mitsuba 3 defines: a directional light E straight down on a diffuse
//! plane gives L = rho E / pi, so each texel of a texture shows as itself.

mod common;

use common::{render_quiet, scratch_dir};
use photonmap::film::Film;
use photonmap::scene::mitsuba::{load, Options};
use photonmap::scene::Scene;
use photonmap::settings::{Method, Settings};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn render(path: &Path, method: Method) -> Result<Film, String> {
    let imported = load(path, &Options::default()).map_err(|e| e.to_string())?;
    let scene = Scene::from_parts(imported.file.parts);
    let settings = Settings {
        method,
        photons: 20_000,
        caustic_photons: 20_000,
        spp: 4,
        width: scene.camera.width,
        height: scene.camera.height,
        ..Settings::default()
    };
    Ok(render_quiet(&scene, &settings))
}

/// A camera 1 above the rectangle [-1, 1]^2 (uv (x + 1) / 2, (y + 1) / 2),
/// seeing exactly it across 16 x 16 pixels (+x right, +y up); a
/// directional light of irradiance 2 straight down; `extra` beside it.
fn plane(bsdf: &str, extra: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
  <integrator type="direct"/>
  <sensor type="perspective"><float name="fov" value="90"/>
    <transform name="to_world"><lookat origin="0,0,1" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle">{bsdf}</shape>
  <emitter type="directional"><vector name="direction" value="0,0,-1"/><rgb name="irradiance" value="2"/></emitter>
  {extra}
</scene>"#
    )
}

/// The mean of the 4 x 4 pixels around the centre of the plane's quadrant
/// (right: +x, top: +y), a channel.
fn quadrant(film: &Film, right: bool, top: bool, channel: usize) -> f64 {
    let (x0, y0) = (if right { 10 } else { 2 }, if top { 2 } else { 10 });
    let mut sum = 0.0;
    for y in y0..y0 + 4 {
        for x in x0..x0 + 4 {
            sum += film.get(x, y)[channel] as f64;
        }
    }
    sum / 16.0
}

const E_OVER_PI: f64 = 2.0 / PI;

/// Mitsuba's checkerboard: color0 where u and v are both in the lower or
/// both in the upper half of a unit, color1 elsewhere.
#[test]
fn a_checkerboard_alternates_as_mitsuba_places_it() {
    let dir = scratch_dir("mitsuba_checkerboard");
    let bsdf = r#"<bsdf type="diffuse"><texture name="reflectance" type="checkerboard">
        <rgb name="color0" value="0.8"/><rgb name="color1" value="0.2"/></texture></bsdf>"#;
    let film = render(&write(&dir, "c.xml", &plane(bsdf, "")), Method::Photon).unwrap();
    for (right, top, rho) in [(false, false, 0.8), (true, true, 0.8), (true, false, 0.2), (false, true, 0.2)] {
        let got = quadrant(&film, right, top, 1);
        assert!((got - rho * E_OVER_PI).abs() < 1e-4, "right {right}, top {top}: {got}");
    }
}

/// A 2 x 2 image, nearest lookup: its first row (v near 0) lies along the
/// plane's bottom edge, as Mitsuba reads rows; 8-bit values are sRGB
/// unless `raw`.
#[test]
fn an_image_shows_each_texel_where_mitsuba_puts_it() {
    let dir = scratch_dir("mitsuba_bitmap");
    // Row 0: 255, 128; row 1: 64, 0 (grey).
    let img = image::GrayImage::from_raw(2, 2, vec![255, 128, 64, 0]).unwrap();
    img.save(dir.join("t.png")).unwrap();
    let decode = |v: f64| {
        let c = v / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    for raw in [false, true] {
        let bsdf = format!(
            r#"<bsdf type="diffuse"><texture name="reflectance" type="bitmap"><string name="filename" value="t.png"/>
               <string name="filter_type" value="nearest"/><boolean name="raw" value="{raw}"/></texture></bsdf>"#
        );
        let film = render(&write(&dir, "b.xml", &plane(&bsdf, "")), Method::Photon).unwrap();
        let value = |v: f64| if raw { v / 255.0 } else { decode(v) };
        for (right, top, texel) in [(false, false, 255.0), (true, false, 128.0), (false, true, 64.0), (true, true, 0.0)]
        {
            let got = quadrant(&film, right, top, 0);
            let want = value(texel) * E_OVER_PI;
            assert!((got - want).abs() < 1e-4, "raw {raw}, right {right}, top {top}: {got} vs {want}");
        }
    }
}

/// A PLY face colour read through mesh_attribute, blended with a fixed
/// diffuse by a face weight (blendbsdf): each triangle shows its own.
#[test]
fn mesh_attributes_and_blends_colour_each_face() {
    let dir = scratch_dir("mitsuba_attributes");
    write(
        &dir,
        "q.ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
         element face 2\nproperty list uchar int vertex_indices\nproperty float r\nproperty float g\n\
         property float b\nproperty float weight\nend_header\n\
         -1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2 0.9 0.1 0.1 0\n3 0 2 3 0.1 0.1 0.9 1\n",
    );
    let text = plane("", "").replace(
        r#"<shape type="rectangle"></shape>"#,
        r#"<shape type="ply"><string name="filename" value="q.ply"/>
             <bsdf type="blendbsdf"><texture name="weight" type="mesh_attribute"><string name="name" value="face_weight"/></texture>
               <bsdf type="diffuse"><texture name="reflectance" type="mesh_attribute"><string name="name" value="face_color"/></texture></bsdf>
               <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></bsdf></shape>"#,
    );
    let film = render(&write(&dir, "a.xml", &text), Method::Photon).unwrap();
    // Below the diagonal y = x: the first face (weight 0: its colour).
    let (r, b) = (quadrant(&film, true, false, 0), quadrant(&film, true, false, 2));
    assert!((r - 0.9 * E_OVER_PI).abs() < 1e-4 && (b - 0.1 * E_OVER_PI).abs() < 1e-4, "{r} {b}");
    // Above it: weight 1, the second BSDF.
    let b = quadrant(&film, false, true, 2);
    assert!((b - 0.5 * E_OVER_PI).abs() < 1e-4, "{b}");
}

/// A mask of opacity 1/4 over a small twosided diffuse square near the
/// camera: the centre shows 1/4 of the square and 3/4 of the floor behind
/// it, seen straight through (the light's shadow of the square falls
/// outside the view).
#[test]
fn a_mask_lets_the_rest_through() {
    let dir = scratch_dir("mitsuba_mask");
    let text = r#"<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,2" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.05"/><translate z="1.5"/></transform>
    <bsdf type="mask"><float name="opacity" value="0.25"/>
      <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf></bsdf></bsdf></shape>
  <emitter type="directional"><vector name="direction" value="1,0,-1"/><rgb name="irradiance" value="2"/></emitter>
</scene>"#;
    let film = render(&write(&dir, "m.xml", text), Method::Photon).unwrap();
    let cos = std::f64::consts::FRAC_1_SQRT_2;
    let want = (0.25 * 0.2 + 0.75 * 0.6) * 2.0 * cos / PI;
    let centre: f64 =
        [(7, 7), (8, 7), (7, 8), (8, 8)].iter().map(|&(x, y)| film.get(x, y)[1] as f64).sum::<f64>() / 4.0;
    // Light the square sends down onto the floor and back is a small
    // second-order term: within 2%.
    assert!((centre - want).abs() < 0.02 * want, "{centre} vs {want}");
    let floor = 0.6 * 2.0 * cos / PI;
    assert!((film.get(1, 1)[1] as f64 - floor).abs() < 0.02 * floor, "{}", film.get(1, 1)[1]);
    // Mitsuba's null BSDF: nothing there, the floor seen whole.
    let null = text.replace(
        r#"<bsdf type="mask"><float name="opacity" value="0.25"/>
      <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf></bsdf></bsdf>"#,
        r#"<bsdf type="null"/>"#,
    );
    assert!(null.contains("null"));
    let film = render(&write(&dir, "n.xml", &null), Method::Photon).unwrap();
    let centre = film.get(8, 8)[1] as f64;
    assert!((centre - floor).abs() < 1e-3 * floor, "{centre} vs {floor}");
}

/// A normal map's flat texel (0.5, 0.5, 1) changes nothing; one that tips
/// the normal by 30 degrees towards +x leaves cos 30 of the light.
#[test]
fn a_normal_map_turns_the_normal() {
    let dir = scratch_dir("mitsuba_normalmap");
    let with = |value: &str| {
        let bsdf = format!(
            r#"<bsdf type="normalmap"><texture name="normalmap" type="rawconstant"><vector name="value" value="{value}"/></texture>
               <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></bsdf>"#
        );
        render(&write(&dir, "n.xml", &plane(&bsdf, "")), Method::Photon).unwrap()
    };
    let flat = with("0.5, 0.5, 1");
    assert!((flat.mean() - 0.5 * E_OVER_PI).abs() < 1e-4, "{}", flat.mean());
    let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    let tipped = with(&format!("{}, 0.5, {}", 0.5 + 0.5 * s, 0.5 + 0.5 * c));
    assert!((tipped.mean() - 0.5 * c * E_OVER_PI).abs() < 1e-4, "{}", tipped.mean());
}

/// A spot light projecting a 2 x 1 image (red left, green right in the
/// image) onto the plane from above: Mitsuba's u runs along the spot's
/// own +x (spot.cpp), which its lookat's up and direction place.
#[test]
fn a_spot_projects_its_image_the_way_mitsuba_does() {
    let dir = scratch_dir("mitsuba_spot_texture");
    let img = image::RgbImage::from_raw(2, 1, vec![255, 0, 0, 0, 255, 0]).unwrap();
    img.save(dir.join("rg.png")).unwrap();
    let spot = r#"<emitter type="spot"><rgb name="intensity" value="1"/><float name="cutoff_angle" value="60"/>
        <float name="beam_width" value="60"/>
        <texture name="texture" type="bitmap"><string name="filename" value="rg.png"/><string name="filter_type" value="nearest"/></texture>
        <transform name="to_world"><lookat origin="0,0,0.5" target="0,0,0" up="0,1,0"/></transform></emitter>"#;
    let text = plane(r#"<bsdf type="diffuse"><rgb name="reflectance" value="1"/></bsdf>"#, spot)
        .replace(r#"<rgb name="irradiance" value="2"/>"#, r#"<rgb name="irradiance" value="0"/>"#);
    let film = render(&write(&dir, "s.xml", &text), Method::Photon).unwrap();
    // The spot's frame: z = -world z, y = world y, x = y cross z = -world x.
    // u < 0.5 (red) is towards the spot's -x: world +x, the image's right.
    let (right_red, left_red) = (quadrant(&film, true, false, 0), quadrant(&film, false, false, 0));
    let (right_green, left_green) = (quadrant(&film, true, false, 1), quadrant(&film, false, false, 1));
    assert!(right_red > 0.0 && right_green == 0.0, "{right_red} {right_green}");
    assert!(left_green > 0.0 && left_red == 0.0, "{left_red} {left_green}");
}

/// What is not supported is refused at its place.
#[test]
fn texture_refusals_are_located() {
    let dir = scratch_dir("mitsuba_texture_refusals");
    let cases = [
        (r#"<bsdf type="diffuse"><texture name="reflectance" type="noise"/></bsdf>"#, "texture 'noise'"),
        (
            r#"<bsdf type="mask"><bsdf type="normalmap"><texture name="normalmap" type="checkerboard"/><bsdf type="conductor"/></bsdf></bsdf>"#,
            "a normal or bump map inside a blend or mask",
        ),
        (r#"<bsdf type="blendbsdf"><bsdf type="diffuse"/></bsdf>"#, "needs two nested <bsdf>"),
        (
            r#"<bsdf type="diffuse"><texture name="reflectance" type="bitmap"><string name="filename" value="none.png"/></texture></bsdf>"#,
            "none.png",
        ),
        (
            r#"<bsdf type="diffuse"><texture name="reflectance" type="bitmap"><string name="filename" value="t.png"/><string name="wrap_mode" value="spiral"/></texture></bsdf>"#,
            "'spiral' is not repeat, mirror or clamp",
        ),
    ];
    image::GrayImage::from_raw(1, 1, vec![7]).unwrap().save(dir.join("t.png")).unwrap();
    for (bsdf, said) in cases {
        let f = write(&dir, "r.xml", &plane(bsdf, ""));
        let e = render(&f, Method::Photon).expect_err("refused");
        assert!(e.contains("r.xml:") && e.contains(said), "{bsdf}: {e}");
    }
}
