//! Mitsuba's principled BSDFs through the XML front-end, on a plane seen
//! head-on by an orthographic sensor under a directional light along the
//! view: ω_o = ω_i = the normal, where the BSDF has a closed form (Schlick
//! weights 0, the half vector the normal, G = 1), so each pixel is f E.

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

/// The plane [-1, 1]^2 at z = 2 facing the sensor at the origin (looking
/// along +z, 8 x 8 pixels spanning it), lit by irradiance 2 along +z.
fn plane(bsdf: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
  <integrator type="direct"/>
  <sensor type="orthographic">
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="180"/><translate z="2"/></transform>{bsdf}</shape>
  <emitter type="directional"><vector name="direction" value="0,0,1"/><rgb name="irradiance" value="2"/></emitter>
</scene>"#
    )
}

fn render(path: &Path) -> Result<Film, String> {
    let imported = load(path, &Options::default()).map_err(|e| e.to_string())?;
    let scene = Scene::from_parts(imported.file.parts);
    let settings = Settings {
        method: Method::Photon,
        spp: 4,
        width: scene.camera.width,
        height: scene.camera.height,
        ..Settings::default()
    };
    Ok(render_quiet(&scene, &settings))
}

fn mean(film: &Film, channel: usize) -> f64 {
    film.pixels.iter().map(|p| p[channel] as f64).sum::<f64>() / film.pixels.len() as f64
}

/// Head-on, a principled of base b, roughness 0.5 (alpha 0.25), specular
/// 0.5 (eta 1.5) and clearcoat 0.5 (gloss 0: GTR1 of alpha 0.1) has
/// f = b / pi + F D / 4 + 0.25 clearcoat F_cc D_cc, F = F_cc = 0.04,
/// D = 1 / (pi alpha^2), D_cc = (a^2 - 1) / (pi ln(a^2) a^2); metallic 1
/// turns it to F = b, no diffuse lobe; a thin sheet of diff_trans 1
/// reflects half its diffuse lobe.
#[test]
fn a_principled_plane_seen_head_on_is_its_closed_form() {
    let dir = scratch_dir("mitsuba_principled_plane");
    let d = 1.0 / (PI * 0.25f64.powi(2));
    let a2 = 0.01f64;
    let d_cc = (a2 - 1.0) / (PI * a2.ln() * a2);
    let base = [0.6, 0.4, 0.2];
    let cases = [
        (
            r#"<bsdf type="principled"><rgb name="base_color" value="0.6, 0.4, 0.2"/><float name="clearcoat" value="0.5"/></bsdf>"#,
            base.map(|b| b / PI + 0.04 * d / 4.0 + 0.25 * 0.5 * 0.04 * d_cc),
        ),
        (
            r#"<bsdf type="principled"><rgb name="base_color" value="0.6, 0.4, 0.2"/><float name="metallic" value="1"/></bsdf>"#,
            base.map(|b| b * d / 4.0),
        ),
        (
            r#"<bsdf type="principledthin"><rgb name="base_color" value="0.6, 0.4, 0.2"/><float name="diff_trans" value="1"/></bsdf>"#,
            base.map(|b| 0.5 * b / PI),
        ),
    ];
    for (i, (bsdf, f)) in cases.iter().enumerate() {
        let film = render(&write(&dir, &format!("p{i}.xml"), &plane(bsdf))).unwrap();
        for (c, f) in f.iter().enumerate() {
            let (got, want) = (mean(&film, c), 2.0 * f);
            assert!((got - want).abs() < 1e-3 * want, "{bsdf}: channel {c}: {got} vs {want}");
        }
    }
}

/// Every parameter Mitsuba lets a texture give takes one: a checkerboard
/// of two values shows as two values on the plane (with the lobes the
/// parameter acts on turned on beside it).
#[test]
fn every_principled_parameter_takes_a_texture() {
    let dir = scratch_dir("mitsuba_principled_textures");
    let checker = |name: &str, a: f32, b: f32| {
        format!(
            r#"<texture name="{name}" type="checkerboard"><float name="color0" value="{a}"/><float name="color1" value="{b}"/></texture>"#
        )
    };
    let cases = [
        ("principled", "base_color", ""),
        ("principled", "roughness", ""),
        ("principled", "metallic", ""),
        ("principled", "spec_trans", ""),
        ("principled", "spec_tint", ""),
        ("principled", "clearcoat", ""),
        ("principled", "clearcoat_gloss", r#"<float name="clearcoat" value="0.5"/>"#),
        ("principled", "flatness", ""),
        ("principledthin", "base_color", ""),
        ("principledthin", "roughness", r#"<float name="spec_trans" value="0.5"/>"#),
        ("principledthin", "spec_trans", ""),
        ("principledthin", "eta", r#"<float name="spec_trans" value="0.5"/>"#),
        ("principledthin", "diff_trans", ""),
        ("principledthin", "spec_tint", r#"<float name="spec_trans" value="0.5"/>"#),
        ("principledthin", "flatness", ""),
    ];
    for (kind, name, extra) in cases {
        let (a, b) = if name == "eta" { (1.2, 1.8) } else { (0.1, 0.9) };
        let fixed = [
            ("base_color", r#"<rgb name="base_color" value="0.6, 0.4, 0.2"/>"#),
            ("roughness", r#"<float name="roughness" value="0.4"/>"#),
        ];
        let others: String = fixed.iter().filter(|(n, _)| *n != name).map(|(_, x)| *x).collect();
        let bsdf = format!(r#"<bsdf type="{kind}">{others}{extra}{}</bsdf>"#, checker(name, a, b));
        let film = render(&write(&dir, "t.xml", &plane(&bsdf))).unwrap_or_else(|e| panic!("{kind} {name}: {e}"));
        let spread = (0..3)
            .map(|c| {
                let (lo, hi) =
                    film.pixels.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p[c]), hi.max(p[c])));
                (hi - lo) / hi.max(1e-6)
            })
            .fold(0.0f32, f32::max);
        assert!(spread > 0.01, "{kind} {name}: a texture made no difference ({spread})");
    }
}

/// What Mitsuba refuses, and what photonmap refuses beside: both eta and
/// specular, a weight outside its documented range, a sampling rate of 0
/// (a lobe never sampled), a parameter neither has; each at its place.
#[test]
fn bad_principled_parameters_are_refused_at_their_place() {
    let dir = scratch_dir("mitsuba_principled_bad");
    for (bsdf, says) in [
        (
            r#"<bsdf type="principled"><float name="eta" value="1.4"/><float name="specular" value="0.3"/></bsdf>"#,
            "either eta or specular",
        ),
        (r#"<bsdf type="principled"><float name="metallic" value="1.5"/></bsdf>"#, "metallic"),
        (r#"<bsdf type="principledthin"><float name="diff_trans" value="2.5"/></bsdf>"#, "diff_trans"),
        (
            r#"<bsdf type="principled"><float name="clearcoat_sampling_rate" value="0"/></bsdf>"#,
            "clearcoat_sampling_rate",
        ),
        (r#"<bsdf type="principledthin"><float name="clearcoat" value="0.5"/></bsdf>"#, "'clearcoat' is not supported"),
    ] {
        let err = render(&write(&dir, "bad.xml", &plane(bsdf))).expect_err(bsdf);
        assert!(err.contains("bad.xml:6:") && err.contains(says), "{bsdf}: {err}");
    }
}
