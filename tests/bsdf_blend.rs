//! Blends of any two materials and masks over any material (Mitsuba's
//! `blendbsdf` and `mask`): the choice of one material per hit
//! (`material::Mix::pick`, what the scene does) against the blend as a
//! whole: sampled directions against the blend's pdf (χ²), white
//! furnaces, the sampled albedo against the weighted albedos; and in
//! scenes, photon mapping against path tracing where photons must be
//! stored on a blend whichever material a photon met, and a plane seen
//! head-on against its closed form.

mod common;

use common::chi2::Chi2;
use common::{render_quiet, scratch_dir};
use glam::Vec3;
use photonmap::film::Film;
use photonmap::material::{Distribution, Lobe, Masked, Material, Mix, Principled, Transport};
use photonmap::math::Color;
use photonmap::sampling::{next_2d, stream, uniform_cone, Domain};
use photonmap::scene::mitsuba::{load, Options};
use photonmap::scene::Scene;
use photonmap::settings::{Method, Settings};
use std::f32::consts::PI;
use std::path::Path;

fn incidences() -> [Vec3; 3] {
    [
        Vec3::new(0.2, 0.1, 0.97).normalize(),
        Vec3::new(0.55, 0.35, 0.6).normalize(),
        Vec3::new(0.75, -0.6, 0.18).normalize(),
    ]
}

fn null() -> Material {
    Material::Masked(Masked { opacity: 0.0, rho: Color::ZERO })
}

/// Pairs (name, weight, first, second): every kind of lobe beside every
/// other, transmission, and masks (null first) over non-diffuse materials.
fn pairs() -> Vec<(&'static str, f32, Material, Material)> {
    let diffuse = Material::Lambertian { rho: Color::new(0.8, 0.5, 0.2) };
    let gold = Material::rough_conductor(
        Distribution::Ggx,
        0.2,
        0.2,
        Color::new(0.14, 0.37, 1.44),
        Color::new(3.98, 2.39, 1.6),
        Color::ONE,
    );
    let frosted = Material::rough_dielectric(Distribution::Beckmann, 0.3, 0.3, 1.5, 1.0, Color::ONE, Color::ONE);
    let plastic =
        Material::rough_plastic(Distribution::Ggx, 0.15, Color::new(0.2, 0.6, 0.3), Color::ONE, 1.49, 1.0, false);
    let mut principled = Principled::new(Color::new(0.3, 0.5, 0.9));
    principled.spec_trans = 0.5;
    principled.roughness = 0.4;
    vec![
        ("diffuse + rough gold", 0.3, diffuse, gold),
        ("rough gold + frosted glass", 0.6, gold, frosted),
        ("principled + rough plastic", 0.5, Material::Principled(principled), plastic),
        ("smooth plastic + diffuse", 0.4, Material::plastic(Color::splat(0.5), Color::ONE, 1.49, 1.0, false), diffuse),
        ("mask 0.7 over rough plastic", 0.7, null(), plastic),
        ("mask 0.4 over frosted glass", 0.4, null(), frosted),
    ]
}

/// The picked material's smooth samples follow the blend's pdf (the
/// specular branches, deltas, left out: the pdf's mass is the rest).
#[test]
fn picked_samples_follow_the_blends_pdf() {
    let cases: Vec<_> = pairs().into_iter().flat_map(|p| incidences().map(move |wo| (p, wo))).collect();
    let n = cases.len();
    let mut failed = Vec::new();
    for (i, ((name, w, a, b), wo)) in cases.into_iter().enumerate() {
        let mix = Mix { weight: w, first: &a, second: &b };
        let mut rng = stream(900 + i as u64, Domain::Camera, 0);
        for entering in [true, false] {
            let o = Chi2 { tests: 2 * n, ..Chi2::default() }.run(
                || {
                    mix.sample(wo, entering, Transport::Radiance, &mut rng)
                        .filter(|s| s.lobe != Lobe::Specular)
                        .map(|s| s.wi.normalize())
                },
                |wi| mix.pdf(wo, wi, entering) as f64,
            );
            println!(
                "{name} wo {wo:.2} entering {entering}: chi2 {:.1} dof {} p {:.4} mass {:.4}",
                o.statistic, o.dof, o.p_value, o.pdf_mass
            );
            if !o.passed() {
                failed.push(format!("{name} {wo} {entering}: p {}", o.p_value));
            }
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
}

fn albedo(mix: &Mix, wo: Vec3, entering: bool, n: usize, seed: u64) -> Color {
    let mut rng = stream(seed, Domain::Camera, 0);
    let mut sum = glam::DVec3::ZERO;
    for _ in 0..n {
        if let Some(s) = mix.sample(wo, entering, Transport::Importance, &mut rng) {
            sum += s.weight.as_dvec3();
        }
    }
    (sum / n as f64).as_vec3()
}

/// The picked material's samples carry, on average, what the blend
/// reflects and transmits: its smooth lobes' f |cos| integrated over
/// uniform directions plus its specular branches' shares.
#[test]
fn the_sampled_albedo_is_the_blends() {
    for (name, w, a, b) in pairs() {
        let mix = Mix { weight: w, first: &a, second: &b };
        for wo in incidences() {
            for entering in [true, false] {
                let n = 300_000;
                let got = albedo(&mix, wo, entering, n, 3);
                let mut rng = stream(4, Domain::Camera, 0);
                let mut smooth = glam::DVec3::ZERO;
                for _ in 0..n {
                    let wi = uniform_cone(next_2d(&mut rng), -1.0);
                    smooth += (mix.eval(wo, wi, entering, Transport::Importance) * wi.z.abs() * 4.0 * PI).as_dvec3();
                }
                let branches: Color = mix
                    .specular_branches(wo, entering, Transport::Importance)
                    .iter()
                    .map(|(share, b)| *share * b.scale)
                    .sum();
                let want = (smooth / n as f64).as_vec3() + branches;
                let err = (got - want).abs().max_element();
                assert!(err < 0.015 + 0.03 * want.max_element(), "{name} wo {wo} entering {entering}: {got} vs {want}");
            }
        }
    }
}

/// White furnaces: a mask over a white material passes or reflects all
/// of it (but what the material loses); a blend of white materials keeps
/// the weighted sum of what each keeps, never more than 1.
#[test]
fn white_furnaces() {
    let white = Material::Lambertian { rho: Color::ONE };
    let white_metal = Material::rough_conductor(Distribution::Ggx, 0.1, 0.1, Color::ZERO, Color::ONE, Color::ONE);
    let white_glass = Material::rough_dielectric(Distribution::Ggx, 0.1, 0.1, 1.5, 1.0, Color::ONE, Color::ONE);
    let n = 300_000;
    for wo in incidences() {
        let mask = Mix { weight: 0.35, first: &null(), second: &white };
        assert!((albedo(&mask, wo, true, n, 5).x - 1.0).abs() < 2e-3, "mask over white diffuse");
        for (first, second) in [(&white_metal, &white_glass), (&white, &white_metal), (&null(), &white_glass)] {
            let mix = Mix { weight: 0.6, first, second };
            let got = albedo(&mix, wo, true, n, 6).x;
            let each = |m: &Material| albedo(&Mix { weight: 0.0, first: m, second: m }, wo, true, n, 7).x;
            let want = 0.4 * each(first) + 0.6 * each(second);
            println!("white blend wo.z {:.2}: {got:.4} vs {want:.4}", wo.z);
            assert!(got <= 1.0 + 3e-3 && (got - want).abs() < 6e-3, "{got} vs {want}");
            if wo.z > 0.5 {
                assert!(got > 0.96, "alpha 0.1 loses under 4%: {got}");
            }
        }
    }
}

fn render(path: &Path, method: Method, spp: u32) -> Film {
    let imported = load(path, &Options::default()).unwrap();
    let scene = Scene::from_parts(imported.file.parts);
    let settings = Settings {
        method,
        photons: 200_000,
        caustic_photons: 100_000,
        spp,
        width: scene.camera.width,
        height: scene.camera.height,
        ..Settings::default()
    };
    render_quiet(&scene, &settings)
}

/// A closed box whose floor is a blend of a diffuse and a rough gold
/// BSDF, a glass ball throwing its caustic on it and a mask over a rough
/// plastic hanging beside: photon mapping's image agrees with the path
/// tracer's, in the mean and per block of pixels. Photons landing on the
/// floor are stored whichever material they met there; stored only where
/// they met the diffuse one, the block holding the caustic came out 10%
/// short of the path tracer's.
#[test]
fn blends_and_masks_in_a_box_agree_with_the_path_tracer() {
    let dir = scratch_dir("blend_box");
    let xml = r#"<scene version="3.0.0"><integrator type="path"/>
  <sensor type="perspective"><float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,-1.6,1.5" target="0,0.1,0.1" up="0,0,1"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/><rfilter type="box"/></film>
  </sensor>
  <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.7"/></bsdf>
  <bsdf type="blendbsdf" id="floor"><float name="weight" value="0.5"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.5, 0.3"/></bsdf>
    <bsdf type="roughconductor"><float name="alpha" value="0.2"/><string name="material" value="Au"/></bsdf>
  </bsdf>
  <bsdf type="mask" id="leaf"><float name="opacity" value="0.6"/>
    <bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.2, 0.7, 0.3"/></bsdf>
  </bsdf>
  <shape type="rectangle"><ref id="floor"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="180"/><translate z="2"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="90"/><translate y="1" z="1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="90"/><translate x="-1" z="1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="-90"/><translate x="1" z="1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="70"/><translate x="0.55" y="0.4" z="0.5"/></transform><ref id="leaf"/></shape>
  <shape type="sphere"><point name="center" x="-0.1" y="0" z="0.75"/><float name="radius" value="0.3"/><bsdf type="dielectric"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.25"/><rotate x="1" angle="180"/><translate z="1.98"/></transform>
    <emitter type="area"><rgb name="radiance" value="15"/></emitter></shape>
</scene>"#;
    let path = dir.join("box.xml");
    std::fs::write(&path, xml).unwrap();
    let photon = render(&path, Method::Photon, 64);
    let path_traced = render(&path, Method::Path, 1024);
    let block = |f: &Film, r0: u32, c0: u32| {
        let mut s = 0.0f64;
        for r in r0..r0 + 8 {
            for c in c0..c0 + 8 {
                s += f.get(c, r).element_sum() as f64;
            }
        }
        s
    };
    let (mut a, mut b) = (0.0, 0.0);
    for r0 in [0, 8, 16] {
        for c0 in [0, 8, 16] {
            let (x, y) = (block(&photon, r0, c0), block(&path_traced, r0, c0));
            println!("block ({r0}, {c0}): photon mapping {x:.2}, path tracing {y:.2}");
            assert!((x - y).abs() < 0.04 * y, "block ({r0}, {c0}): {x} vs {y}");
            (a, b) = (a + x, b + y);
        }
    }
    assert!((a - b).abs() < 0.015 * b, "mean: {a} vs {b}");
}

/// Seen head-on under a light along the view (an orthographic sensor), a
/// blend of a diffuse reflectance 0.8 and a white rough metal (Beckmann,
/// alpha 0.5: D = 1 / (pi alpha^2), F = G = 1) with weight 0.25 shows
/// 0.75 (0.8 / pi) + 0.25 D / 4 per unit irradiance: the weight is the
/// second BSDF's share, as in Mitsuba.
#[test]
fn a_blend_seen_head_on_is_its_weighted_closed_form() {
    let dir = scratch_dir("blend_plane");
    let xml = r#"<scene version="3.0.0"><integrator type="direct"/>
  <sensor type="orthographic">
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="180"/><translate z="2"/></transform>
    <bsdf type="blendbsdf"><float name="weight" value="0.25"/>
      <bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf>
      <bsdf type="roughconductor"><float name="alpha" value="0.5"/></bsdf>
    </bsdf></shape>
  <emitter type="directional"><vector name="direction" value="0,0,1"/><rgb name="irradiance" value="2"/></emitter>
</scene>"#;
    let path = dir.join("plane.xml");
    std::fs::write(&path, xml).unwrap();
    let film = render(&path, Method::Photon, 256);
    let got = film.pixels.iter().map(|p| p.x as f64).sum::<f64>() / film.pixels.len() as f64;
    let d = 1.0 / (std::f64::consts::PI * 0.25);
    let want = 2.0 * (0.75 * 0.8 / std::f64::consts::PI + 0.25 * d / 4.0);
    assert!((got - want).abs() < 0.01 * want, "{got} vs {want}");
}

/// The XML front-end: a blend that refers to itself, and a bump map
/// inside a blend, are refused at their place; a `twosided` blend shows
/// its front from behind too (its one-sided materials made two-sided),
/// where without `twosided` the back of its diffuse and metal is black.
#[test]
fn blends_in_the_front_end() {
    let dir = scratch_dir("blend_front_end");
    let scene = |bsdf: &str, z: f32| {
        format!(
            r#"<scene version="3.0.0"><integrator type="direct"/>
  <sensor type="orthographic">
    <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><translate z="{z}"/></transform>
    {bsdf}</shape>
  <emitter type="directional"><vector name="direction" value="0,0,1"/><rgb name="irradiance" value="2"/></emitter>
</scene>"#
        )
    };
    let load_err = |xml: String| {
        let path = dir.join("s.xml");
        std::fs::write(&path, xml).unwrap();
        load(&path, &Options::default()).map(|_| ()).expect_err("refused").to_string()
    };
    let itself = r#"<bsdf type="blendbsdf" id="b"><ref id="b"/><bsdf type="diffuse"/></bsdf>"#;
    let err = load_err(scene(itself, 2.0));
    assert!(err.contains("s.xml:6:") && err.contains("refer to itself"), "{err}");
    let bumped = r#"<bsdf type="blendbsdf"><bsdf type="bumpmap"><texture type="checkerboard"/><bsdf type="roughconductor"/></bsdf><bsdf type="diffuse"/></bsdf>"#;
    let err = load_err(scene(bumped, 2.0));
    assert!(err.contains("s.xml:6:") && err.contains("bump map inside a blend"), "{err}");
    // The plane's front (+z) faces away from the sensor at the origin.
    let blend = r#"<bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="roughconductor"/></bsdf>"#;
    let lit = |bsdf: String| {
        let path = dir.join("t.xml");
        std::fs::write(&path, scene(&bsdf, 2.0)).unwrap();
        let film = render(&path, Method::Photon, 16);
        film.pixels.iter().map(|p| p.y as f64).sum::<f64>() / film.pixels.len() as f64
    };
    assert_eq!(lit(blend.to_string()), 0.0);
    assert!(lit(format!(r#"<bsdf type="twosided">{blend}</bsdf>"#)) > 0.1);
}
