//! Participating media: the phase functions' sampling against their
//! densities (χ²), a homogeneous slab's transmittance against
//! Beer–Lambert, the heterogeneous estimators against a fine quadrature,
//! the `.vol` format through the Mitsuba front-end (its values read back,
//! bad files refused at their byte), energy (a medium that does not absorb
//! keeps a furnace uniform), the same image on any number of threads, and
//! the front-end's refusals at their file, line and column.

mod common;

use common::chi2::Chi2;
use common::{render_quiet, scratch_dir};
use glam::{Affine3A, Vec3};
use photonmap::math::{Color, Ray};
use photonmap::medium::{Filter, Flight, Grid, Medium, Phase, VolGrid, Volume, Wrap};
use photonmap::sampling::{next_2d, stream, Domain};
use photonmap::scene::mitsuba::{load, Options};
use photonmap::scene::Scene;
use photonmap::settings::{Method, Settings};
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn read(path: &Path) -> Result<Scene, String> {
    load(path, &Options::default()).map(|i| Scene::from_parts(i.file.parts)).map_err(|e| e.to_string())
}

fn path_traced(scene: &Scene, spp: u32) -> photonmap::film::Film {
    let settings = Settings {
        method: Method::Path,
        spp,
        width: scene.camera.width,
        height: scene.camera.height,
        ..Settings::default()
    };
    render_quiet(scene, &settings)
}

/// Isotropic and Henyey–Greenstein (forward, backward, strongly forward)
/// sampling against their densities, from several travel directions.
#[test]
fn phase_functions_sample_their_density() {
    let phases = [
        Phase::Isotropic,
        Phase::HenyeyGreenstein { g: 0.3 },
        Phase::HenyeyGreenstein { g: -0.5 },
        Phase::HenyeyGreenstein { g: 0.8 },
        Phase::HenyeyGreenstein { g: 0.0 },
    ];
    let dirs = [Vec3::Z, Vec3::new(0.6, -0.3, 0.74).normalize(), Vec3::new(-0.2, 0.9, -0.4).normalize()];
    let tests = phases.len() * dirs.len();
    let mut failed = Vec::new();
    for (i, phase) in phases.iter().enumerate() {
        for (j, dir) in dirs.iter().enumerate() {
            let mut rng = stream(500 + (i * 7 + j) as u64, Domain::Camera, 0);
            let chi2 = Chi2 { tests, ..Chi2::default() };
            let o = chi2.run(|| Some(phase.sample(*dir, next_2d(&mut rng)).0), |w| phase.eval(*dir, w) as f64);
            println!(
                "{phase:?} from {dir}: chi2 {:.1} dof {} p {:.4} mass {:.4}",
                o.statistic, o.dof, o.p_value, o.pdf_mass
            );
            if !o.passed() || (o.pdf_mass - 1.0).abs() > 1e-3 {
                failed.push(format!("{phase:?} {dir}: p {} mass {}", o.p_value, o.pdf_mass));
            }
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
}

/// χ²: single scattering's distances drawn by transmittance times a grid
/// of where the lights reach (`LitSegment`), grey, chromatic and nearly
/// clear media, a segment ending inside the grid and one reaching to
/// infinity, a heterogeneous medium's box drawn by the segment's
/// transmittance across it, and the same segment tracked (drawn as its
/// σ_t T falls, [`LitSegment::build`]), follow the density they report (40 bins along the first
/// `span` of the segment and one for the rest; each bin's expected count
/// is the density integrated by a 4,000-step midpoint rule, the jumps at
/// the cells' ends within it costing under 10⁻⁴ of a bin).
#[test]
fn lit_distances_follow_their_density() {
    use photonmap::medium::{LitGrid, LitSegment, Steps};
    let albedo = Volume::Constant { value: Color::ONE, to_world: Affine3A::IDENTITY };
    let grid = LitGrid::speckled(3);
    let cases = [
        (Color::splat(0.2), Vec3::new(-1.5, 0.1, 0.3), Vec3::new(1.0, 0.2, 0.35), 6.0, 6.0),
        (Color::new(0.1, 0.8, 3.0), Vec3::new(2.5, 1.2, 1.9), Vec3::new(-1.0, -0.3, -0.5), 5.0, 5.0),
        (Color::splat(1e-6), Vec3::new(0.0, 0.0, 0.5), Vec3::new(0.3, 0.1, 0.2), 4.0, 4.0),
        (Color::new(0.5, 0.6, 0.7), Vec3::new(0.0, 0.2, 0.5), Vec3::new(0.3, 0.1, 0.2), f32::INFINITY, 12.0),
        // Heterogeneous (`smoke()`, its box [-1, 1]³): the colour is the
        // transmittance across the segment, one channel nearly clear.
        (Color::new(0.3, 0.6, 0.999_99), Vec3::new(-1.5, 0.1, 0.3), Vec3::new(1.0, 0.2, 0.35), 6.0, 6.0),
        // The same smoke, the segment tracked: drawn as σ_t T falls along
        // it, each channel's (the grid's three differ).
        (Color::ONE, Vec3::new(-1.5, 0.1, 0.3), Vec3::new(1.0, 0.2, 0.35), 6.0, 6.0),
    ];
    let chi2 = Chi2 { samples: 200_000, tests: cases.len(), ..Chi2::default() };
    let mut failed = Vec::new();
    for (k, &(sigma, o, d, t_max, span)) in cases.iter().enumerate() {
        let (heterogeneous, tracked) = (k >= cases.len() - 2, k == cases.len() - 1);
        let m = match heterogeneous {
            true => smoke(),
            false => Medium::homogeneous(sigma, albedo.clone(), 1.0, Phase::Isotropic).unwrap(),
        };
        let ray = Ray::new(o, d.normalize());
        let mut seg = LitSegment::default();
        let mut steps = Steps::default();
        let across = match (heterogeneous, tracked) {
            (_, true) => m.track(&ray, t_max, &mut steps),
            (true, false) => sigma,
            _ => Color::ONE,
        };
        assert!(seg.build(&m, &grid, &ray, t_max, across, &steps), "case {k}");
        let bins = 40;
        let bin = |t: f32| if t >= span { bins } else { ((t / span * bins as f32) as usize).min(bins - 1) };
        let mut observed = vec![0.0f64; bins + 1];
        let mut rng = stream(9, Domain::Camera, k as u64);
        for _ in 0..chi2.samples {
            let (t, pdf) = seg.sample(next_2d(&mut rng)).unwrap();
            assert!(t >= 0.0 && t <= t_max, "case {k}: {t}");
            let want = seg.pdf(t);
            assert!((pdf - want).abs() <= 1e-4 * want, "case {k}: pdf {pdf} against {want} at {t}");
            observed[bin(t)] += 1.0;
        }
        let mut expected = vec![0.0f64; bins + 1];
        let steps = 4000 * bins;
        let h = span as f64 / steps as f64;
        for i in 0..steps {
            let t = (i as f64 + 0.5) * h;
            expected[bin(t as f32)] += seg.pdf(t as f32) as f64 * h;
        }
        let inside: f64 = expected.iter().sum();
        // Beyond the span (case 4): the rest of the density's mass.
        let mass = if t_max > span {
            let tail = 1.0 - inside;
            assert!(tail > 0.0 && tail < 0.2, "case {k}: tail {tail}");
            expected[bins] = tail;
            1.0
        } else {
            inside
        };
        assert!((mass - 1.0).abs() < 1e-3, "case {k}: the density integrates to {mass}");
        expected.iter_mut().for_each(|e| *e *= chi2.samples as f64);
        let out = chi2.pearson(&observed, &expected, mass);
        println!("case {k}: chi2 {:.1} dof {} p {:.4}", out.statistic, out.dof, out.p_value);
        if !out.passed() {
            failed.push(format!("case {k}: {out:?}"));
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
}

/// An orthographic view along -z through a cube of absorbing medium
/// (albedo 0) of thickness 2, bounded by a null BSDF, at a rectangle
/// glowing with radiance 1: every ray crosses exactly 2 of medium, so
/// every pixel is exp(-2 σ_t) per channel, to rounding; the part of the
/// view beside the cube sees the light unattenuated.
#[test]
fn a_homogeneous_slab_transmits_exactly_beer_lambert() {
    let dir = scratch_dir("media_slab");
    let sigma = [0.1f32, 0.7, 2.5];
    let text = format!(
        r#"<scene version="3.0.0">
  <sensor type="orthographic">
    <transform name="to_world"><scale x="2" y="2"/><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
  </sensor>
  <medium type="homogeneous" id="fog">
    <rgb name="sigma_t" value="{}, {}, {}"/><float name="albedo" value="0"/><float name="scale" value="0.5"/>
  </medium>
  <shape type="cube"><bsdf type="null"/><ref name="interior" id="fog"/>
    <transform name="to_world"><scale x="1" y="4" z="1"/></transform></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="5"/><translate z="-3"/></transform>
    <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
</scene>"#,
        2.0 * sigma[0],
        2.0 * sigma[1],
        2.0 * sigma[2]
    );
    let scene = read(&write(&dir, "slab.xml", &text)).unwrap();
    let film = path_traced(&scene, 4);
    let want = Color::new((-2.0 * sigma[0]).exp(), (-2.0 * sigma[1]).exp(), (-2.0 * sigma[2]).exp());
    let (mut through, mut beside) = (0, 0);
    for row in 0..16 {
        for col in 0..16 {
            // The film spans x in [-2, 2]: the cube's x in [-1, 1] is columns 4..12.
            let v = film.get(col, row);
            if (5..11).contains(&col) {
                through += 1;
                assert!(((v - want) / want).abs().max_element() <= 1e-5, "({col}, {row}): {v} vs {want}");
            } else if !(3..13).contains(&col) {
                beside += 1;
                assert_eq!(v, Color::ONE, "({col}, {row}) sees the light past the cube");
            }
        }
    }
    assert_eq!((through, beside), (6 * 16, 6 * 16));
}

/// A grid of smoothly varying values over the unit cube, 3 channels of
/// different densities, placed by a transform that scales and moves it.
fn smoke() -> Medium {
    let n = 12u32;
    let mut data = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let (fx, fy, fz) = (x as f32 / n as f32, y as f32 / n as f32, z as f32 / n as f32);
                let v = 0.5 + 0.5 * (6.0 * fx + 2.0 * fy).sin() * (4.0 * fz).cos();
                data.extend_from_slice(&[v, 0.3 * v + 0.1, if (x + y + z) % 3 == 0 { 1.0 } else { 0.2 }]);
            }
        }
    }
    let vol = Arc::new(VolGrid { res: [n; 3], channels: 3, bbox: ([0.0; 3], [1.0; 3]), data });
    let to_world = Affine3A::from_translation(Vec3::splat(-1.0)) * Affine3A::from_scale(Vec3::splat(2.0));
    let grid = Grid::new(vol, to_world, false, Filter::Trilinear, Wrap::Clamp).unwrap();
    let albedo = Volume::Constant { value: Color::new(0.9, 0.5, 0.7), to_world: Affine3A::IDENTITY };
    Medium::heterogeneous(Volume::Grid(grid), albedo, 2.0, Phase::Isotropic).unwrap()
}

/// A grid of a few dense puffs in empty space (its coarse cells' local
/// majorants far below its largest value, many of them zero), rotated by
/// 30° (so its box is wider than its cube, whose outside reads by
/// repeating it), looked up at the nearest cell.
fn puffs() -> Medium {
    let n = 32u32;
    let puffs = [(Vec3::new(0.3, 0.4, 0.5), 0.12, 4.0), (Vec3::new(0.7, 0.6, 0.3), 0.08, 9.0)];
    let mut data = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let p = (Vec3::new(x as f32, y as f32, z as f32) + 0.5) / n as f32;
                let v: f32 = puffs.iter().map(|&(c, r, d)| d * (1.0 - p.distance(c) / r).max(0.0)).sum();
                data.extend_from_slice(&[v, 0.5 * v, 0.3 * v + 0.05]);
            }
        }
    }
    let vol = Arc::new(VolGrid { res: [n; 3], channels: 3, bbox: ([0.0; 3], [1.0; 3]), data });
    let to_world = Affine3A::from_rotation_z(30f32.to_radians())
        * Affine3A::from_translation(Vec3::splat(-1.0))
        * Affine3A::from_scale(Vec3::new(2.0, 2.0, 1.5));
    let grid = Grid::new(vol, to_world, false, Filter::Nearest, Wrap::Repeat).unwrap();
    let albedo = Volume::Constant { value: Color::new(0.9, 0.5, 0.7), to_world: Affine3A::IDENTITY };
    Medium::heterogeneous(Volume::Grid(grid), albedo, 1.0, Phase::Isotropic).unwrap()
}

/// exp(-∫ σ_t) along `ray` over [0, t_max] by the midpoint rule in
/// 200,000 steps, and the scattered light's density over it in `bins`
/// bins: ∫ σ_s(t) T(t) dt.
fn quadrature(m: &Medium, ray: &Ray, t_max: f32, bins: usize) -> (glam::DVec3, Vec<glam::DVec3>) {
    let steps = 200_000;
    let dt = t_max as f64 / steps as f64;
    let mut optical = glam::DVec3::ZERO;
    let mut scattered = vec![glam::DVec3::ZERO; bins];
    for i in 0..steps {
        let t = (i as f64 + 0.5) * dt;
        let (sigma_t, sigma_s) = m.coefficients(ray.at(t as f32));
        let mid = optical + sigma_t.as_dvec3() * dt * 0.5;
        let tr = glam::DVec3::new((-mid.x).exp(), (-mid.y).exp(), (-mid.z).exp());
        scattered[i * bins / steps] += sigma_s.as_dvec3() * tr * dt;
        optical += sigma_t.as_dvec3() * dt;
    }
    (glam::DVec3::new((-optical.x).exp(), (-optical.y).exp(), (-optical.z).exp()), scattered)
}

/// Ratio tracking's transmittance and delta tracking's flights through a
/// heterogeneous, chromatic grid are unbiased: their means agree with a
/// fine quadrature of the same lookups within four standard errors, per
/// channel, for the transmittance, the chance-weighted passing flights
/// and the scattered weight in each of 4 stretches of the ray. Both
/// track against local majorants: a smooth grid's, and puffs in empty
/// space rotated so that the rays also cross the box outside its cube.
#[test]
fn heterogeneous_estimators_are_unbiased_against_quadrature() {
    let rays = [
        (Ray::new(Vec3::new(-2.0, -0.3, 0.2), Vec3::X), 4.0),
        (Ray::new(Vec3::new(-0.5, -1.5, -0.7), Vec3::new(0.3, 1.0, 0.5).normalize()), 3.0),
        // Ends inside the grid.
        (Ray::new(Vec3::new(0.2, 0.1, -2.0), Vec3::Z), 2.5),
    ];
    let puffs_rays = [
        // Through both puffs (about (-0.25, -0.37, -0.25) and (0.25,
        // 0.37, -0.55) in the scene).
        (Ray::new(Vec3::new(-1.03, -1.56, 0.23), Vec3::new(0.52, 0.79, -0.32).normalize()), 3.5),
        (Ray::new(Vec3::new(0.35, -1.63, -0.35), Vec3::new(-0.05, 1.0, -0.1).normalize()), 3.5),
        // Across the box's corners outside the cube, ending in a puff.
        (Ray::new(Vec3::new(-2.0, -0.37, -0.25), Vec3::X), 1.8),
    ];
    let media = [(smoke(), rays), (puffs(), puffs_rays)];
    for (k, (m, ray, t_max)) in media.iter().flat_map(|(m, r)| r.iter().map(move |&(ray, t)| (m, ray, t))).enumerate() {
        let bins = 4;
        let (exact, scattered) = quadrature(m, &ray, t_max, bins);
        let n = 200_000;
        let mut rng = stream(77, Domain::Camera, k as u64);
        let (mut tr, mut tr2) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
        let (mut pass, mut pass2) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
        let mut bin = vec![(glam::DVec3::ZERO, glam::DVec3::ZERO); bins];
        for i in 0..n {
            let t = m.transmittance(&ray, t_max, &mut rng).as_dvec3();
            tr += t;
            tr2 += t * t;
            // A throughput that varies, as a path's does, choosing channels.
            let throughput = Color::new(1.0, 0.2 + (i % 5) as f32 * 0.2, 0.5);
            match m.sample_flight(&ray, t_max, throughput, &mut rng) {
                Flight::Passed { weight } => {
                    let w = weight.as_dvec3();
                    pass += w;
                    pass2 += w * w;
                }
                Flight::Scattered { t, weight } => {
                    assert!(t >= 0.0 && t < t_max);
                    let b = ((t / t_max) * bins as f32) as usize;
                    let w = weight.as_dvec3();
                    bin[b.min(bins - 1)].0 += w;
                    bin[b.min(bins - 1)].1 += w * w;
                }
            }
        }
        let check = |what: &str, sum: glam::DVec3, sum2: glam::DVec3, want: glam::DVec3| {
            let mean = sum / n as f64;
            let se = ((sum2 / n as f64 - mean * mean) / n as f64).max(glam::DVec3::ZERO);
            for c in 0..3 {
                let tolerance = 4.0 * se[c].sqrt() + 1e-4;
                assert!(
                    (mean[c] - want[c]).abs() < tolerance,
                    "ray {k} {what} channel {c}: {} vs {}",
                    mean[c],
                    want[c]
                );
            }
            println!("ray {k} {what}: {mean:.5} vs {want:.5}");
        };
        assert!(exact.max_element() < 0.9 && exact.min_element() > 0.01, "ray {k} crosses some smoke: {exact}");
        check("transmittance", tr, tr2, exact);
        check("passing flights", pass, pass2, exact);
        for (b, (s, s2)) in bin.into_iter().enumerate() {
            check(&format!("scattered in stretch {b}"), s, s2, scattered[b]);
        }
    }
}

/// A sensor 32x32 looking at the origin from z = 4, and a furnace: light
/// of radiance 1 from every direction.
fn furnace_scene(body: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  {body}
</scene>"#
    )
}

/// A medium that scatters all it extinguishes (albedo 1) neither makes
/// nor loses light: a ball of it in a white furnace looks exactly like
/// the furnace, radiance 1, through an index-matched or a glass boundary,
/// homogeneous (grey or chromatic, isotropic or forward scattering) or
/// heterogeneous (a grid).
#[test]
fn a_medium_that_does_not_absorb_keeps_the_furnace_white() {
    let dir = scratch_dir("media_furnace");
    let grid = VolGrid {
        res: [4, 4, 4],
        channels: 1,
        bbox: ([0.0; 3], [1.0; 3]),
        data: (0..64).map(|i| [0.2f32, 1.0, 3.0, 0.0][i % 4] + (i / 16) as f32).collect(),
    };
    std::fs::write(dir.join("grid.vol"), grid.to_bytes()).unwrap();
    let cases = [
        ("grey, isotropic, null", r#"<rgb name="sigma_t" value="2"/>"#, "homogeneous", "", r#"<bsdf type="null"/>"#),
        (
            "chromatic, forward",
            r#"<rgb name="sigma_t" value="0.5, 2, 4"/>"#,
            "homogeneous",
            r#"<phase type="hg"><float name="g" value="0.7"/></phase>"#,
            r#"<bsdf type="null"/>"#,
        ),
        ("grey, glass", r#"<rgb name="sigma_t" value="1.5"/>"#, "homogeneous", "", r#"<bsdf type="dielectric"/>"#),
        (
            "grid, backward",
            r#"<volume name="sigma_t" type="gridvolume"><string name="filename" value="grid.vol"/>
               <transform name="to_world"><scale value="2"/><translate value="-1"/></transform></volume>"#,
            "heterogeneous",
            r#"<phase type="hg"><float name="g" value="-0.4"/></phase>"#,
            r#"<bsdf type="null"/>"#,
        ),
    ];
    for (name, sigma, kind, phase, bsdf) in cases {
        let body = format!(
            r#"<shape type="sphere">{bsdf}<medium type="{kind}" name="interior">{sigma}<float name="albedo" value="1"/>{phase}</medium></shape>"#
        );
        let scene = read(&write(&dir, "f.xml", &furnace_scene(&body))).unwrap();
        assert!(scene.media().is_some());
        let film = path_traced(&scene, 512);
        let mean = film.pixels.iter().copied().sum::<Color>() / film.pixels.len() as f32;
        // Uniform: every 4x4 block of pixels (8,192 paths) near 1.
        let block = |bx: u32, by: u32| (0..16).map(|i| film.get(4 * bx + i % 4, 4 * by + i / 4)).sum::<Color>() / 16.0;
        let worst = (0..16).map(|b| (block(b % 4, b / 4) - Color::ONE).abs().max_element()).fold(0.0, f32::max);
        println!("{name}: mean {mean}, worst 4x4 block off by {worst}");
        assert!((mean - Color::ONE).abs().max_element() < 0.01, "{name}: mean {mean}");
        assert!(worst < 0.05, "{name}: a block of pixels is off by {worst}");
    }
}

/// A grid written as a `.vol` file and read by the front-end is the
/// medium's extinction: its cells at their centres, times the scale;
/// nothing outside the grid's box.
#[test]
fn a_vol_file_reads_back_through_the_front_end() {
    let dir = scratch_dir("media_vol");
    let data: Vec<f32> = (0..2 * 3 * 4).map(|i| i as f32 * 0.5).collect();
    let grid = VolGrid { res: [2, 3, 4], channels: 1, bbox: ([10.0, 0.0, 0.0], [12.0, 3.0, 4.0]), data: data.clone() };
    std::fs::write(dir.join("g.vol"), grid.to_bytes()).unwrap();
    assert_eq!(VolGrid::read(&dir.join("g.vol")).unwrap(), grid);
    let body = r#"<shape type="cube"><bsdf type="null"/>
      <medium type="heterogeneous" name="interior"><float name="scale" value="2"/>
        <volume name="sigma_t" type="gridvolume"><string name="filename" value="g.vol"/>
          <boolean name="use_grid_bbox" value="true"/><string name="filter_type" value="nearest"/>
          <transform name="to_world"><translate x="-10"/></transform></volume></medium></shape>"#;
    let scene = read(&write(&dir, "v.xml", &furnace_scene(body))).unwrap();
    let medium = &scene.media().unwrap().media[0];
    for z in 0..4 {
        for y in 0..3 {
            for x in 0..2 {
                // The file's box [10, 12] x [0, 3] x [0, 4], moved by -10 in x.
                let p = Vec3::new(x as f32 + 0.5, y as f32 + 0.5, z as f32 + 0.5);
                let want = 2.0 * data[(z * 3 + y) * 2 + x];
                assert_eq!(medium.coefficients(p).0, Color::splat(want), "cell ({x}, {y}, {z})");
            }
        }
    }
    assert_eq!(medium.coefficients(Vec3::new(2.5, 0.5, 0.5)).0, Color::ZERO);
}

/// Each mistake in a scene's media is refused at the place it is written
/// (file, line, column), naming what is supported; so is a bad `.vol`
/// file, at its byte.
#[test]
fn unsupported_media_are_refused_where_written() {
    let dir = scratch_dir("media_refusals");
    let good = VolGrid { res: [1, 1, 1], channels: 1, bbox: ([0.0; 3], [1.0; 3]), data: vec![1.0] }.to_bytes();
    let mut bad = good.clone();
    bad[3] = 2;
    std::fs::write(dir.join("good.vol"), &good).unwrap();
    std::fs::write(dir.join("bad.vol"), &bad).unwrap();
    let grid = |file: &str, more: &str| {
        format!(r#"<volume name="sigma_t" type="gridvolume"><string name="filename" value="{file}"/>{more}</volume>"#)
    };
    // (the medium, the element the error is at, what it says)
    let cases: Vec<(String, &str, &str)> = vec![
        (r#"<medium type="fancy" id="m"/>"#.into(), "<medium", "the 'fancy' medium is not supported (homogeneous and heterogeneous are)"),
        (
            r#"<medium type="homogeneous" id="m"><phase type="rayleigh"/></medium>"#.into(),
            "<phase",
            "the 'rayleigh' phase function is not supported (isotropic and hg are)",
        ),
        (
            r#"<medium type="heterogeneous" id="m"><volume name="sigma_t" type="sdf"/></medium>"#.into(),
            "<volume",
            "the 'sdf' volume is not supported (gridvolume and constvolume are)",
        ),
        (
            r#"<medium type="homogeneous" id="m"><float name="albedo" value="1.2"/></medium>"#.into(),
            "<medium",
            "the albedo must lie in [0, 1]",
        ),
        (
            format!(r#"<medium type="homogeneous" id="m">{}</medium>"#, grid("good.vol", "")),
            "<volume",
            "a homogeneous medium's sigma_t is a colour or a constvolume",
        ),
        (format!(r#"<medium type="heterogeneous" id="m">{}</medium>"#, grid("bad.vol", "")), "<string", "byte 3: version 2"),
        (format!(r#"<medium type="heterogeneous" id="m">{}</medium>"#, grid("none.vol", "")), "<string", "cannot find 'none.vol'"),
        (
            format!(r#"<medium type="heterogeneous" id="m">{}</medium>"#, grid("good.vol", r#"<float name="max_value" value="3"/>"#)),
            r#"<float name="max_value""#,
            "'max_value' is not supported by photonmap's 'gridvolume' volume",
        ),
        (
            format!(r#"<medium type="heterogeneous" id="m">{}</medium>"#, grid("good.vol", r#"<string name="wrap_mode" value="wobble"/>"#)),
            r#"<string name="wrap_mode""#,
            "'wobble' is not clamp, repeat or mirror",
        ),
        (
            r#"<medium type="homogeneous" id="m"><phase type="hg"><float name="g" value="1"/></phase></medium>"#.into(),
            r#"<float name="g""#,
            "must lie in (-1, 1), got 1",
        ),
        (
            r#"<medium type="homogeneous" id="m"><float name="sigma_s" value="1"/><float name="albedo" value="0.5"/></medium>"#.into(),
            r#"<float name="albedo""#,
            "give sigma_t and albedo, or sigma_s and sigma_a, not both",
        ),
    ];
    for (i, (medium, at, message)) in cases.iter().enumerate() {
        let body = format!("{medium}<shape type=\"sphere\"><ref name=\"interior\" id=\"m\"/></shape>");
        // The body is line 8 of the file, from column 3.
        let column = 3 + body.find(at).unwrap();
        let f = write(&dir, &format!("r{i}.xml"), &furnace_scene(&body));
        let err = read(&f).err().unwrap_or_else(|| panic!("case {i} loads"));
        assert!(err.contains(&format!("r{i}.xml:8:{column}:")), "case {i}: not at 8:{column}: {err}");
        assert!(err.contains(message), "case {i}: {err}");
    }
    // A shape's medium is its interior or exterior.
    let body = r#"<medium type="homogeneous" id="m"/><shape type="sphere"><ref name="inside" id="m"/></shape>"#;
    let err = read(&write(&dir, "n.xml", &furnace_scene(body))).err().expect("refused");
    assert!(err.contains("a shape's medium is named 'interior' or 'exterior'"), "{err}");
}

/// The same seed gives the same image of a scene with media on one thread
/// or two.
#[test]
fn media_render_the_same_on_any_number_of_threads() {
    let dir = scratch_dir("media_threads");
    let body = r#"<shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior">
      <rgb name="sigma_t" value="1, 2, 3"/><rgb name="albedo" value="0.8, 0.6, 0.9"/></medium></shape>
      <shape type="rectangle"><transform name="to_world"><scale value="3"/><translate z="-2"/></transform>
      <bsdf type="diffuse"/></shape>"#;
    let scene = read(&write(&dir, "t.xml", &furnace_scene(body))).unwrap();
    let films: Vec<_> = [1, 2]
        .into_iter()
        .map(|threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| path_traced(&scene, 8))
        })
        .collect();
    assert!(films[0].pixels.iter().any(|p| *p != Color::ONE));
    assert_eq!(films[0], films[1]);
}

/// A scene's media written for Mitsuba 3 (`export --mitsuba`) and read
/// back give the same media, on the same shapes and the camera, and the
/// same image (in the mean).
#[test]
fn media_export_and_import_agree() {
    use photonmap::export::mitsuba::{to_mitsuba, Placement};
    let dir = scratch_dir("media_export");
    let grid = VolGrid {
        res: [3, 2, 2],
        channels: 3,
        bbox: ([0.0; 3], [2.0; 3]),
        data: (0..36).map(|i| 0.1 * (i % 7) as f32).collect(),
    };
    std::fs::write(dir.join("g.vol"), grid.to_bytes()).unwrap();
    let body = r#"<medium type="homogeneous" id="air"><rgb name="sigma_t" value="0.05, 0.1, 0.2"/>
        <rgb name="albedo" value="0.9, 0.8, 0.7"/><phase type="hg"><float name="g" value="0.4"/></phase></medium>
      <shape type="sphere"><float name="radius" value="10"/><bsdf type="null"/><ref name="interior" id="air"/></shape>
      <shape type="cube"><bsdf type="dielectric"/><ref name="exterior" id="air"/>
        <medium type="heterogeneous" name="interior"><float name="scale" value="3"/>
          <volume name="sigma_t" type="gridvolume"><string name="filename" value="g.vol"/>
            <boolean name="use_grid_bbox" value="true"/><string name="wrap_mode" value="mirror"/>
            <transform name="to_world"><translate value="-1"/></transform></volume>
          <volume name="albedo" type="constvolume"><rgb name="value" value="0.5"/></volume></medium></shape>
      <shape type="rectangle"><transform name="to_world"><scale value="3"/><translate z="-2"/></transform>
        <bsdf type="twosided"><bsdf type="diffuse"/></bsdf></shape>"#;
    let text = furnace_scene(body).replace("</sensor>", r#"<ref name="medium" id="air"/></sensor>"#);
    let imported = load(&write(&dir, "a.xml", &text), &Options::default()).unwrap();
    let parts = imported.file.parts;
    let exported = to_mitsuba(&parts, None, "files", Placement::new(Vec3::ZERO, 1.0).unwrap()).unwrap();
    std::fs::create_dir_all(dir.join("files")).unwrap();
    for (name, bytes) in &exported.meshes {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    assert!(exported.meshes.iter().any(|(n, _)| n.ends_with(".vol")), "the grid is written beside the meshes");
    let again = load(&write(&dir, "b.xml", &exported.xml), &Options::default()).unwrap().file.parts;
    assert_eq!(again.media.media.len(), 2);
    assert_eq!(again.media.camera, parts.media.camera);
    let (a, b) = (Scene::from_parts(parts), Scene::from_parts(again));
    let mut rng = stream(3, Domain::Camera, 0);
    for _ in 0..200 {
        let p = Vec3::new(-1.5, -1.5, -1.5)
            + 3.0 * Vec3::new(next_2d(&mut rng).x, next_2d(&mut rng).y, next_2d(&mut rng).x);
        for m in 0..2 {
            let (x, y) = (a.media().unwrap().media[m].coefficients(p), b.media().unwrap().media[m].coefficients(p));
            assert!(
                (x.0 - y.0).abs().max_element() <= 1e-5 * x.0.max_element().max(1.0),
                "medium {m} at {p}: {x:?} vs {y:?}"
            );
            assert!(
                (x.1 - y.1).abs().max_element() <= 1e-5 * x.1.max_element().max(1.0),
                "medium {m} at {p}: {x:?} vs {y:?}"
            );
        }
    }
    // The export's sensor starts its rays at another near plane, so the
    // two images are the same in the mean, not to the bit.
    let (fa, fb) = (path_traced(&a, 64), path_traced(&b, 64));
    let mean = |f: &photonmap::film::Film| f.pixels.iter().copied().sum::<Color>() / f.pixels.len() as f32;
    let (ma, mb) = (mean(&fa), mean(&fb));
    assert!(((ma - mb) / ma).abs().max_element() < 0.01, "means {ma} and {mb}");
}

/// A scene file (TOML) with a homogeneous medium around the camera and a
/// ball of heterogeneous smoke from a `.vol` grid inside it.
fn toml_scene(media: &str, ball: &str) -> String {
    format!(
        r#"[camera]
eye = [0, 0, 4]
target = [0, 0, 0]
up = [0, 1, 0]
vfov = 40
width = 16
height = 16
medium = "fog"

[materials.boundary]
type = "null"

[materials.wall]
type = "lambertian"
rho = [0.5, 0.5, 0.5]

{media}

[[shapes]]
type = "sphere"
material = "boundary"
center = [0, 0, 0]
radius = 1
{ball}

[[shapes]]
type = "quad"
material = "wall"
vertices = [[-3, -3, -2], [3, -3, -2], [3, 3, -2], [-3, 3, -2]]

[[lights]]
type = "point"
position = [0, 2, 3]
color = [5, 5, 5]
"#
    )
}

const TOML_MEDIA: &str = r#"[media.fog]
type = "homogeneous"
sigma_t = [0.1, 0.2, 0.3]
albedo = [0.9, 0.9, 0.9]
phase = { type = "hg", g = 0.3 }

[media.smoke]
type = "heterogeneous"
sigma_t = { grid = "g.vol", transform = [{ scale = [2, 2, 2] }, { translate = [-1, -1, -1] }] }
scale = 2
albedo = [0.5, 0.6, 0.7]"#;

/// The scene file reads media as the XML front-end does: their
/// coefficients, the grid placed by its transform, the shapes that bound
/// them, the camera's; and the scene renders.
#[test]
fn scene_files_hold_media() {
    let dir = scratch_dir("media_toml");
    let data: Vec<f32> = (0..8).map(|i| i as f32).collect();
    std::fs::write(
        dir.join("g.vol"),
        VolGrid { res: [2, 2, 2], channels: 1, bbox: ([0.0; 3], [1.0; 3]), data }.to_bytes(),
    )
    .unwrap();
    let path = write(&dir, "m.toml", &toml_scene(TOML_MEDIA, "interior = \"smoke\"\nexterior = \"fog\""));
    let file = photonmap::scene::file::load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(file.meshes.contains(&dir.join("g.vol")), "the grid is an input of the scene");
    let scene = Scene::from_parts(file.parts);
    let media = scene.media().expect("the scene has media");
    // Media by name: fog then smoke.
    assert_eq!(media.camera, Some(0));
    let fog = &media.media[0];
    assert!(fog.is_homogeneous() && fog.phase == Phase::HenyeyGreenstein { g: 0.3 });
    assert_eq!(fog.coefficients(Vec3::new(7.0, 0.0, 0.0)).0, Color::new(0.1, 0.2, 0.3));
    let smoke = &media.media[1];
    // The corner cell (1, 1, 1) holds 7, centred at (0.5, 0.5, 0.5); scale 2.
    let (sigma_t, sigma_s) = smoke.coefficients(Vec3::splat(0.5));
    assert_eq!(sigma_t, Color::splat(14.0));
    assert!((sigma_s - Color::new(7.0, 8.4, 9.8)).abs().max_element() < 1e-5);
    // The sphere is primitive 0: smoke inside, fog outside; the wall bounds nothing.
    assert_eq!(media.after(None, 0, Vec3::Z, -Vec3::Z), Some(1));
    assert_eq!(media.after(None, 0, Vec3::Z, Vec3::Z), Some(0));
    assert_eq!(media.after(Some(1), 1, Vec3::Z, Vec3::Z), Some(1));
    let film = path_traced(&scene, 4);
    assert!(film.mean() > 0.0);
}

/// Mistakes in a scene file's media are refused at their place.
#[test]
fn scene_file_media_mistakes_are_refused_where_written() {
    let dir = scratch_dir("media_toml_refusals");
    let mut bad = VolGrid { res: [1, 1, 1], channels: 1, bbox: ([0.0; 3], [1.0; 3]), data: vec![1.0] }.to_bytes();
    bad[20] = 2;
    std::fs::write(dir.join("g.vol"), &bad).unwrap();
    // (the media, the ball's fields, the text the error is at, what it says)
    let fog = "[media.fog]\ntype = \"homogeneous\"\n";
    let cases: Vec<(String, &str, &str, &str)> = vec![
        (
            "[media.fog]\ntype = \"gas\"".into(),
            "",
            "\"gas\"",
            "unknown medium type \"gas\" (homogeneous, heterogeneous)",
        ),
        (
            format!("{fog}sigma = [1, 1, 1]"),
            "",
            "sigma =",
            "unknown field `sigma`: it does not apply to type \"homogeneous\"",
        ),
        (format!("{fog}albedo = [1.5, 1, 1]"), "", "\"homogeneous\"", "the albedo must lie in [0, 1]"),
        (format!("{fog}sigma_t = [1, 1, 1]\nsigma_s = [1, 1, 1]"), "", "[1, 1, 1]\nsigma_s", "not both"),
        (format!("{fog}phase = {{ type = \"hg\", g = 1.0 }}"), "", "1.0 }", "must lie in (-1, 1), got 1"),
        (format!("{fog}phase = {{ type = \"rayleigh\" }}"), "", "\"rayleigh\"", "unknown phase function \"rayleigh\""),
        (fog.into(), "interior = \"smog\"", "\"smog\"", "no medium named \"smog\" (defined: fog)"),
        (
            format!("{fog}[media.smoke]\ntype = \"heterogeneous\"\nsigma_t = {{ grid = \"g.vol\" }}"),
            "",
            "\"g.vol\"",
            "byte 20: 2 channels (photonmap reads 1 or 3)",
        ),
        (
            format!(
                "{fog}[media.smoke]\ntype = \"heterogeneous\"\nsigma_t = {{ value = [1, 1, 1], grid = \"g.vol\" }}"
            ),
            "",
            "{ value",
            "a volume is a constant `value` or a `grid` file",
        ),
    ];
    for (i, (media, ball, at, message)) in cases.iter().enumerate() {
        let text = toml_scene(media, ball);
        let offset = text.find(at).unwrap_or_else(|| panic!("case {i}: no {at:?}"));
        let line = text[..offset].matches('\n').count() + 1;
        let column = offset - text[..offset].rfind('\n').map_or(0, |n| n + 1) + 1;
        let path = write(&dir, &format!("r{i}.toml"), &text);
        let err = match photonmap::scene::file::load(&path) {
            Ok(_) => panic!("case {i} loads"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains(&format!("r{i}.toml:{line}:{column}:")), "case {i}: not at {line}:{column}: {err}");
        assert!(err.contains(message), "case {i}: {err}");
    }
}
