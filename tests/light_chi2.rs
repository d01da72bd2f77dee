//! Every light's sampling against its density (χ², tests/common/chi2.rs),
//! for each kind: point, spot (plain and through an image), projector,
//! directional, disk, triangle, emissive mesh, constant sky, environment
//! map.
//!
//! - Shadow-ray samples (`sample_li`) against their density (`pdf_li`,
//!   which MIS reads); a delta light's one direction, exactly.
//! - Photon starts (`sample_le`) against their densities (`pdf_le`): the
//!   direction over the sphere, the position over the light's surface or
//!   the disk across parallel light, mapped onto the unit square.
//! - The photons the photon pass emits, weighted by their power, against
//!   what the light sends, written here from each light's definition (its
//!   radiant intensity over directions, its irradiance over the disk):
//!   the global pass's, the caustic pass's aimed at glass spheres (only
//!   what the light sends towards them), and each light's aimed photons
//!   (`sample_le_towards`) for any aim. A weighted χ² (each cell's power
//!   against its expectation, over its sampled variance) tests power and
//!   direction together: a wrong density, weight or power fails it.

mod common;

use common::chi2::{Chi2, Outcome};
use glam::{Affine2, Mat3, Vec2, Vec3};
use photonmap::camera::Camera;
use photonmap::envmap::EnvMap;
use photonmap::film::Film;
use photonmap::light::{
    Aim, AreaLight, Constant, Directional, Emitting, Environment, Light, PointLight, Projector, Spot,
};
use photonmap::material::Material;
use photonmap::math::{Color, Frame, Ray};
use photonmap::photon::aims::specular_targets;
use photonmap::photon::trace::{emit, Pass};
use photonmap::sampling::{concentric_disk, next_2d, photon_points, stream, uniform_cone, Domain, Rng};
use photonmap::scene::{PathLimits, Prim, Scene, SceneParts};
use photonmap::shape::{Disk, Shape, Sphere, Triangle};
use photonmap::texture::{SurfacePoint, Texture};
use std::f64::consts::PI;
use std::sync::Arc;

/// The box the lights are placed around (light from infinity starts
/// outside it).
const LO: Vec3 = Vec3::new(-1.0, -1.0, -1.0);
const HI: Vec3 = Vec3::new(1.0, 1.0, 1.0);

fn sum(c: Color) -> f64 {
    (c.x + c.y + c.z) as f64
}

fn envmap() -> Arc<EnvMap> {
    let (w, h) = (32, 16);
    let pixels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if (20..23).contains(&x) && (4..6).contains(&y) {
                Color::new(20.0, 16.0, 12.0)
            } else {
                Color::new(0.2, 0.3, 0.5) * (1.0 + (y as f32) / h as f32)
            }
        })
        .collect();
    Arc::new(EnvMap::new(&Film { width: w, height: h, pixels }, 1.0, Mat3::IDENTITY))
}

fn spot_frame() -> Frame {
    Frame::from_normal(Vec3::new(0.2, -0.3, 1.0).normalize())
}

fn checker() -> Arc<Texture> {
    let to_uv = Affine2::from_scale(Vec2::splat(3.0));
    Arc::new(Texture::Checkerboard { color0: Color::new(1.0, 0.5, 0.2), color1: Color::new(0.1, 0.2, 0.4), to_uv })
}

fn disk() -> Disk {
    Disk { center: Vec3::new(0.2, 0.1, 0.9), normal: Vec3::new(0.2, -0.1, -1.0).normalize(), radius: 0.4 }
}

fn triangle() -> Triangle {
    Triangle::new(Vec3::new(-0.5, -0.4, 0.8), Vec3::new(0.3, 0.6, 0.9), Vec3::new(0.6, -0.5, 0.7))
}

fn projector() -> Projector {
    let f = Frame::from_normal(Vec3::new(-0.3, 0.1, -1.0).normalize());
    Projector {
        position: Vec3::new(0.1, 0.2, 0.5),
        axes: [f.s, f.t, f.n],
        scaled: Color::new(3.0, 2.0, 1.0),
        tan_x: 0.6,
        tan_y: 0.35,
        pattern: None,
    }
}

/// Every kind of light, placed around the box.
fn lights() -> Vec<(&'static str, Light)> {
    let spot = || Spot::new(Vec3::new(0.1, -0.2, 0.3), spot_frame(), Color::new(2.0, 1.5, 1.0), 40.0, 25.0);
    let mut lights = vec![
        (
            "point",
            Light::Point(PointLight {
                position: Vec3::new(0.3, -0.2, 0.1),
                intensity: Color::new(2.0, 1.0, 0.5),
                falloff: 2.0,
                dead_distance: 0.0,
            }),
        ),
        ("spot", Light::Spot(spot())),
        ("spot with an image", Light::Spot(spot().with_pattern(checker()))),
        ("projector", Light::Projector(projector())),
        ("directional", Light::Directional(Directional::new(Vec3::new(0.3, 0.2, -1.0).normalize(), Color::ONE))),
        ("disk", Light::Area(AreaLight::new(Emitting::Disk(disk()), Color::new(1.0, 2.0, 3.0), 0))),
        ("triangle", Light::Area(AreaLight::new(Emitting::Triangle(triangle()), Color::new(3.0, 2.0, 1.0), 0))),
        ("constant sky", Light::Constant(Constant::new(Color::new(0.5, 0.7, 1.0)))),
        ("environment map", Light::Envmap(Environment::new(envmap()))),
    ];
    for (_, l) in &mut lights {
        l.place(LO, HI);
    }
    lights
}

/// What the light sends per unit solid angle towards `d` (radiant
/// intensity, summed over channels), from its definition; `None` for light
/// from infinity (sent across a disk, not from a point).
fn intensity(light: &Light, d: Vec3) -> Option<f64> {
    match light {
        Light::Point(p) => Some(sum(p.intensity)),
        Light::Spot(s) => {
            // Mitsuba's spot (spot.cpp): full out to the beam angle, then
            // linear in angle to zero at the cutoff.
            let (cutoff, beam) = (40f64.to_radians(), 25f64.to_radians());
            let f = spot_frame();
            let l = Vec3::new(d.dot(f.s), d.dot(f.t), d.dot(f.n));
            let theta = (l.z as f64).clamp(-1.0, 1.0).acos();
            let falloff = if theta <= beam {
                1.0
            } else if theta < cutoff {
                (cutoff - theta) / (cutoff - beam)
            } else {
                0.0
            };
            // Its image maps the cone onto uv as 0.5 + 0.5 (x, y) / (z tan cutoff).
            let image = if falloff > 0.0 && s.pattern_at(Vec3::new(0.0, 0.0, 1.0)) != Color::ONE {
                let k = 0.5 / (l.z as f64 * cutoff.tan());
                let uv = Vec2::new((0.5 + l.x as f64 * k) as f32, (0.5 + l.y as f64 * k) as f32);
                checker().eval(&SurfacePoint { uv, prim: 0, bary: Vec2::ZERO })
            } else {
                Color::ONE
            };
            Some(sum(s.intensity * image) * falloff)
        }
        Light::Projector(p) => {
            // π E s / cos³θ inside the frustum (projector.cpp).
            let l = Vec3::new(d.dot(p.axes[0]), d.dot(p.axes[1]), d.dot(p.axes[2]));
            let inside = l.z > 0.0 && l.x.abs() <= p.tan_x * l.z && l.y.abs() <= p.tan_y * l.z;
            Some(if inside { sum(p.scaled) / (l.z as f64).powi(3) } else { 0.0 })
        }
        // Lambertian: L A cos θ towards the front.
        Light::Area(a) => Some(sum(a.radiance) * a.area() as f64 * d.dot(a.surface.normal()).max(0.0) as f64),
        Light::Directional(_) | Light::Constant(_) | Light::Envmap(_) => None,
    }
}

/// Radiance (summed over channels) arriving from unit direction
/// `towards` of light from infinity.
fn radiance_from(light: &Light, towards: Vec3) -> f64 {
    match light {
        Light::Constant(c) => sum(c.radiance),
        Light::Envmap(e) => sum(e.map.eval(towards)),
        _ => 0.0,
    }
}

fn report(name: &str, what: &str, o: &Outcome, failed: &mut Vec<String>) {
    eprintln!(
        "{name}, {what}: chi2 {:.1} dof {} p {:.4} (level {:.5}) mass {:.4}",
        o.statistic, o.dof, o.p_value, o.threshold, o.pdf_mass
    );
    if !o.passed() {
        failed.push(format!("{name}, {what}: p {:.2e}", o.p_value));
    }
}

/// A point `p` of a disk (`center`, unit `normal`, `radius`) as a point of
/// the unit square: (r² / R², φ / 2π) in the disk's frame, which maps
/// uniform points of the disk to uniform points of the square.
fn disk_to_square(center: Vec3, normal: Vec3, radius: f32, p: Vec3) -> Vec2 {
    let f = Frame::from_normal(normal);
    let d = p - center;
    let (x, y) = (d.dot(f.s) / radius, d.dot(f.t) / radius);
    let phi = (y as f64).atan2(x as f64).rem_euclid(2.0 * PI);
    Vec2::new(x * x + y * y, (phi / (2.0 * PI)) as f32)
}

/// The inverse of [`disk_to_square`].
fn square_to_disk(center: Vec3, normal: Vec3, radius: f32, u: f64, v: f64) -> Vec3 {
    let f = Frame::from_normal(normal);
    let (r, phi) = (u.sqrt() * radius as f64, 2.0 * PI * v);
    center + f.s * (r * phi.cos()) as f32 + f.t * (r * phi.sin()) as f32
}

/// A point of a triangle as a point of the unit square: the inverse of
/// the square-root warp ((b1 + b2)², b2 / (b1 + b2)), which maps uniform
/// points of the triangle to uniform points of the square.
fn triangle_to_square(t: &Triangle, p: Vec3) -> Vec2 {
    let (e1, e2, q) = (t.v1 - t.v0, t.v2 - t.v0, p - t.v0);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (q1, q2) = (q.dot(e1), q.dot(e2));
    let det = d11 * d22 - d12 * d12;
    let b1 = (d22 * q1 - d12 * q2) / det;
    let b2 = (d11 * q2 - d12 * q1) / det;
    let s = b1 + b2;
    Vec2::new(s * s, if s > 0.0 { b2 / s } else { 0.0 })
}

fn square_to_triangle(t: &Triangle, u: f64, v: f64) -> Vec3 {
    let su = u.sqrt();
    let (b1, b2) = ((su * (1.0 - v)) as f32, (su * v) as f32);
    t.v0 * (1.0 - b1 - b2) + t.v1 * b1 + t.v2 * b2
}

/// Shading points about the lights: in front, oblique, beside.
fn points() -> [(Vec3, Vec3); 3] {
    [
        (Vec3::new(0.0, 0.0, 0.0), Vec3::Z),
        (Vec3::new(0.7, -0.4, 0.2), Vec3::new(0.3, 0.1, 1.0).normalize()),
        (Vec3::new(-1.5, 0.3, 0.3), Vec3::new(-0.6, 0.0, 0.8).normalize()),
    ]
}

/// Shadow-ray samples against the density MIS weighs them by, at three
/// points: the area lights, the sky (cosine about the normal), the
/// environment map. A sample's own density (`pdf_li_of`) is the one found
/// again from its direction alone. A delta light's samples are its one
/// direction, of no density (no sampled direction meets it).
#[test]
fn shadow_ray_samples_follow_their_density() {
    let lights = lights();
    let sampled: Vec<_> = lights.iter().filter(|(_, l)| !l.is_delta()).collect();
    let tests = sampled.len() * points().len();
    let mut failed = Vec::new();
    for (i, (name, light)) in sampled.iter().enumerate() {
        for (j, (p, n)) in points().into_iter().enumerate() {
            let mut rng = stream(31, Domain::Camera, (i * 10 + j) as u64);
            let chi2 = Chi2 { cos_bins: 24, phi_bins: 48, tests, ..Chi2::default() };
            let o = chi2.run(
                || light.sample_li(p, n, next_2d(&mut rng)).map(|inc| inc.dir),
                |w| light.pdf_li(p, n, w.normalize()) as f64,
            );
            report(name, &format!("shadow rays at {p:.2}"), &o, &mut failed);
            assert!(o.pdf_mass > 0.01, "{name} at {p}: pdf mass {}", o.pdf_mass);
            let mut differ = 0;
            for _ in 0..10_000 {
                if let Some(inc) = light.sample_li(p, n, next_2d(&mut rng)) {
                    let (a, b) = (light.pdf_li_of(p, n, &inc), light.pdf_li(p, n, inc.dir));
                    assert!(a > 0.0, "{name} at {p}: a sample of density {a}");
                    differ += ((a - b).abs() > 1e-3 * a) as u32;
                }
            }
            assert!(differ < 10, "{name} at {p}: {differ} of 10000 densities differ");
            if light.compensates() {
                // The shadow rays that share light with a cosine strategy.
                let o = chi2.run(
                    || light.sample_li_shared(p, n, next_2d(&mut rng)).map(|inc| inc.dir),
                    |w| light.pdf_li_shared(p, n, w.normalize()) as f64,
                );
                report(name, &format!("shared shadow rays at {p:.2}"), &o, &mut failed);
                assert!(o.pdf_mass > 0.01, "{name} at {p}: shared pdf mass {}", o.pdf_mass);
            }
        }
    }
    assert!(sampled.iter().any(|(_, l)| l.compensates()), "no light tests the shared shadow rays");
    assert!(failed.is_empty(), "{failed:?}");
    for (name, light) in lights.iter().filter(|(_, l)| l.is_delta()) {
        // A point each light reaches: along a spot's or a projector's axis.
        let p = match light {
            Light::Spot(s) => s.position + s.frame.n,
            Light::Projector(pr) => pr.position + pr.axes[2],
            _ => Vec3::new(0.1, -0.1, -0.8),
        };
        let n = Vec3::Z;
        let want = match light {
            Light::Point(l) => (l.position - p).normalize(),
            Light::Spot(s) => (s.position - p).normalize(),
            Light::Projector(pr) => (pr.position - p).normalize(),
            Light::Directional(d) => -d.direction,
            _ => unreachable!(),
        };
        let mut rng = stream(32, Domain::Camera, 0);
        for _ in 0..100 {
            let inc = light.sample_li(p, n, next_2d(&mut rng)).unwrap_or_else(|| panic!("{name}: no light at {p}"));
            assert!((inc.dir - want).length() < 1e-5, "{name}: {} against {want}", inc.dir);
            assert_eq!(light.pdf_li(p, n, inc.dir), 0.0, "{name}");
        }
    }
}

/// Photon starts against their densities: the direction over the sphere,
/// the position over the unit square the surface or disk maps onto (a
/// light at a point starts every photon there; a directional light sends
/// every photon along its direction).
#[test]
fn photon_starts_follow_their_density() {
    let lights = lights();
    let tests = 2 * lights.len();
    let chi2 = Chi2 { cos_bins: 20, phi_bins: 40, samples: 300_000, tests, ..Chi2::default() };
    let mut failed = Vec::new();
    for (i, (name, light)) in lights.iter().enumerate() {
        let mut rng = stream(41, Domain::Camera, i as u64);
        let mut start = || light.sample_le(next_2d(&mut rng), next_2d(&mut rng)).ray;
        // A ray of direction `d` from where the light would start it.
        let from = |d: Vec3| -> Ray {
            match light {
                Light::Area(a) => Ray::new(a.surface.anchor(), d),
                Light::Constant(c) => Ray::new(c.reach.upstream(d), d),
                Light::Envmap(e) => Ray::new(e.reach.upstream(d), d),
                _ => Ray::new(Vec3::ZERO, d),
            }
        };
        match light {
            Light::Directional(d) => {
                for _ in 0..1000 {
                    assert_eq!(start().dir, d.direction, "{name}");
                }
            }
            _ => {
                let o = chi2.run(|| Some(start().dir), |w| light.pdf_le(&from(w.normalize())).1 as f64);
                report(name, "photon directions", &o, &mut failed);
            }
        }
        let mut rng = stream(42, Domain::Camera, i as u64);
        let mut start = || light.sample_le(next_2d(&mut rng), next_2d(&mut rng)).ray;
        // The position's map onto the square, and the square's area per
        // unit of the surface's.
        let o = match light {
            Light::Area(a) => match a.surface {
                Emitting::Disk(d) => chi2.run_square(
                    || Some(disk_to_square(d.center, d.normal, d.radius, start().origin)),
                    |u, v| {
                        let p = square_to_disk(d.center, d.normal, d.radius, u, v);
                        light.pdf_le(&Ray::new(p, d.normal)).0 as f64 * a.area() as f64
                    },
                ),
                Emitting::Triangle(t) => chi2.run_square(
                    || Some(triangle_to_square(&t, start().origin)),
                    |u, v| {
                        let p = square_to_triangle(&t, u, v);
                        light.pdf_le(&Ray::new(p, t.normal)).0 as f64 * a.area() as f64
                    },
                ),
            },
            Light::Point(_) | Light::Spot(_) | Light::Projector(_) => {
                let at = light.bounds().unwrap().0;
                for _ in 0..1000 {
                    assert_eq!(start().origin, at, "{name}");
                    assert_eq!(light.pdf_le(&Ray::new(at, Vec3::Z)).0, 1.0, "{name}");
                }
                continue;
            }
            Light::Constant(_) | Light::Envmap(_) => {
                // Light from infinity: along a fixed direction, starts
                // uniform on the shadow of the scene's box, mapped onto a
                // square of side 4 across the direction about the box's
                // centre (the box of side 2 casts at most 2 √3 across).
                let reach = match light {
                    Light::Constant(c) => c.reach,
                    Light::Envmap(e) => e.reach,
                    _ => unreachable!(),
                };
                let d = Vec3::new(0.3, -0.5, 0.8).normalize();
                let f = Frame::from_normal(d);
                let centre = reach.upstream(d);
                let to_square = |p: Vec3| {
                    let q = p - centre;
                    Vec2::new((q.dot(f.s) + 2.0) / 4.0, (q.dot(f.t) + 2.0) / 4.0)
                };
                let mut rng = stream(43, Domain::Camera, i as u64);
                let o = chi2.run_square(
                    || reach.start(d, next_2d(&mut rng)).map(to_square),
                    |u, v| {
                        let p = centre + f.s * (4.0 * u as f32 - 2.0) + f.t * (4.0 * v as f32 - 2.0);
                        light.pdf_le(&Ray::new(p, d)).0 as f64 * 16.0
                    },
                );
                report(name, "photon starts on the box's shadow", &o, &mut failed);
                continue;
            }
            _ => {
                // Parallel light: the disk across the photon's direction.
                let (c, radius) = match light {
                    Light::Directional(l) => (l.reach.0, l.reach.1),
                    _ => unreachable!(),
                };
                let fixed = match light {
                    Light::Directional(l) => l.direction,
                    _ => unreachable!(),
                };
                let o = chi2.run_square(
                    || {
                        let r = start();
                        Some(disk_to_square(c, r.dir, radius, r.origin))
                    },
                    |u, v| {
                        let p = square_to_disk(c, fixed, radius, u, v);
                        light.pdf_le(&Ray::new(p, fixed)).0 as f64 * PI * (radius as f64).powi(2)
                    },
                );
                report(name, "photon starts on the disk", &o, &mut failed);
                continue;
            }
        };
        report(name, "photon starts on the surface", &o, &mut failed);
    }
    assert!(failed.is_empty(), "{failed:?}");
}

/// A scene of `lights` over a floor far below, with glass spheres
/// (`targets`) to aim caustic photons at.
fn scene(lights: Vec<Light>, targets: &[(Vec3, f32)]) -> Scene {
    let floor =
        Triangle::new(Vec3::new(-50.0, -50.0, -20.0), Vec3::new(50.0, -50.0, -20.0), Vec3::new(0.0, 50.0, -20.0));
    let mut prims = vec![Prim { shape: Shape::Triangle(floor), material: 0, object: 0 }];
    for (i, &(center, radius)) in targets.iter().enumerate() {
        prims.push(Prim { shape: Shape::Sphere(Sphere { center, radius }), material: 1, object: 1 + i as u32 });
    }
    let eye = Vec3::new(0.0, -5.0, 0.0);
    let corners = [
        Vec3::new(-1.0, -4.0, -1.0),
        Vec3::new(1.0, -4.0, -1.0),
        Vec3::new(1.0, -4.0, 1.0),
        Vec3::new(-1.0, -4.0, 1.0),
    ];
    Scene::from_parts(SceneParts {
        prims,
        shading_normals: Vec::new(),
        materials: vec![Material::Lambertian { rho: Color::splat(0.5) }, Material::glass(1.5)],
        lights,
        ambient: Color::ZERO,
        camera: Camera::from_corners(eye, corners, 8, 8),
        one_sided: Vec::new(),
        paths: PathLimits::default(),
        texturing: Default::default(),
        media: Default::default(),
    })
}

/// An unplaced light, as a scene file gives it.
fn unplaced(light: &Light) -> Light {
    match light {
        Light::Area(a) => AreaLight::unplaced(a.surface, a.radiance, None),
        Light::Directional(d) => Light::Directional(Directional::new(d.direction, d.irradiance)),
        Light::Constant(c) => Light::Constant(Constant::new(c.radiance)),
        Light::Envmap(e) => Light::Envmap(Environment::new(e.map.clone())),
        other => other.clone(),
    }
}

/// The global pass's photons from a scene of each light alone: their power
/// (times their number) over directions against the light's radiant
/// intensity (a light from a point or a surface), or over the disk across
/// parallel light against its irradiance there (directional), or over
/// directions against the radiance of light from infinity times the area
/// of the scene box's shadow across them (sky, environment map).
#[test]
fn the_global_pass_emits_what_each_light_sends() {
    let lights = lights();
    let chi2 = Chi2 { cos_bins: 16, phi_bins: 32, samples: 300_000, tests: lights.len(), ..Chi2::default() };
    let mut failed = Vec::new();
    for (i, (name, light)) in lights.iter().enumerate() {
        let scene = scene(vec![unplaced(light)], &[]);
        let placed = &scene.lights[0];
        let n = chi2.samples as u64;
        let mut k = 0;
        let mut next = || {
            k += 1;
            let mut rng = stream(51 + i as u64, Domain::GlobalPhotons, k);
            emit(&scene, &[], Pass::Global, n, &mut rng).1.map(|(ray, _, power)| (ray, sum(power) * n as f64))
        };
        let o = match placed {
            Light::Directional(d) => {
                let (c, r) = d.reach;
                let e = sum(d.irradiance) * PI * (r as f64).powi(2);
                chi2.run_weighted_square(
                    || next().map(|(ray, w)| (disk_to_square(c, d.direction, r, ray.origin), w)),
                    |_, _| e,
                )
            }
            Light::Constant(_) | Light::Envmap(_) => {
                // Across each direction, the box's shadow.
                let reach = match placed {
                    Light::Constant(c) => c.reach,
                    Light::Envmap(e) => e.reach,
                    _ => unreachable!(),
                };
                chi2.run_weighted(
                    || next().map(|(ray, w)| (ray.dir, w)),
                    |d| radiance_from(placed, -d) * reach.area(d) as f64,
                )
            }
            _ => chi2.run_weighted(|| next().map(|(ray, w)| (ray.dir, w)), |d| intensity(placed, d).unwrap()),
        };
        report(name, "global photons' power", &o, &mut failed);
    }
    assert!(failed.is_empty(), "{failed:?}");
}

/// An emissive mesh is a light per triangle: the global pass starts its
/// photons on each triangle in proportion to the triangle's power, each
/// photon with the mesh's power over their number.
#[test]
fn an_emissive_mesh_emits_by_each_triangles_power() {
    let mut rng = stream(61, Domain::Camera, 0);
    let mut lights = Vec::new();
    for i in 0..40 {
        let c = Vec3::new((i % 8) as f32 * 0.25 - 1.0, (i / 8) as f32 * 0.25 - 0.6, 0.5);
        let u = next_2d(&mut rng);
        let size = 0.05 + 0.15 * u.x;
        let t = Triangle::new(c, c + Vec3::new(size, 0.0, 0.0), c + Vec3::new(0.0, size * (0.5 + u.y), 0.0));
        let radiance = Color::new(1.0 + (i % 5) as f32, 2.0, 0.5 + (i % 3) as f32);
        lights.push(AreaLight::unplaced(Emitting::Triangle(t), radiance, None));
    }
    let scene = scene(lights, &[]);
    let powers: Vec<f64> = scene.lights.iter().map(|l| sum(l.power())).collect();
    let total: f64 = powers.iter().sum();
    let first_prim = scene.lights[0].area().unwrap().prim;
    let chi2 = Chi2 { samples: 200_000, ..Chi2::default() };
    let n = chi2.samples as u64;
    let mut k = 0;
    let o = chi2.run_weighted_cells(
        scene.lights.len(),
        || {
            k += 1;
            let mut rng = stream(62, Domain::GlobalPhotons, k);
            let (ray, departure, power) = emit(&scene, &[], Pass::Global, n, &mut rng).1?;
            let light = (departure?.prim - first_prim) as usize;
            let a = scene.lights[light].area()?;
            assert!((ray.origin - a.surface.anchor()).dot(a.surface.normal()).abs() < 1e-5, "off its triangle");
            Some((light, sum(power) * n as f64))
        },
        |cell| powers[cell],
    );
    report("emissive mesh", "photons' power per triangle", &o, &mut Vec::new());
    assert!(o.passed(), "p {}", o.p_value);
    assert!((o.pdf_mass - total).abs() < 1e-6 * total);
}

/// Aimed uniformly: directions over the sphere, starts on a disk of
/// radius 2 about the origin's projection across parallel light.
struct Everywhere;

impl Aim for Everywhere {
    fn direction_from(&self, _origin: Vec3, u: Vec2) -> (Vec3, f32) {
        (uniform_cone(u, -1.0).normalize(), (1.0 / (4.0 * PI)) as f32)
    }

    fn origin_across(&self, direction: Vec3, plane: Vec3, u: Vec2) -> (Vec3, f32) {
        let f = Frame::from_normal(direction);
        let d = concentric_disk(u) * 2.0;
        let c = plane - direction * plane.dot(direction);
        (c + f.s * d.x + f.t * d.y, (1.0 / (PI * 4.0)) as f32)
    }
}

/// Each light's aimed photons, aimed anywhere: their power (what the light
/// sends along them over the density of the aiming) over directions
/// against the light's radiant intensity, or, for light from infinity,
/// the radiance times the aiming disk's area.
#[test]
fn aimed_photons_carry_what_the_light_sends() {
    let lights = lights();
    let chi2 = Chi2 { cos_bins: 16, phi_bins: 32, samples: 300_000, tests: lights.len(), ..Chi2::default() };
    let mut failed = Vec::new();
    for (i, (name, light)) in lights.iter().enumerate() {
        let mut rng: Rng = stream(71, Domain::CausticPhotons, i as u64);
        let mut next =
            || light.sample_le_towards(&Everywhere, &mut rng).map(|a| (a.ray, sum(a.intensity) / a.pdf as f64));
        let o = match light {
            Light::Directional(d) => {
                let c = Vec3::ZERO;
                let e = sum(d.irradiance) * PI * 4.0;
                chi2.run_weighted_square(
                    || {
                        next().map(|(ray, w)| {
                            assert_eq!(ray.dir, d.direction);
                            (
                                disk_to_square(
                                    c,
                                    d.direction,
                                    2.0,
                                    ray.origin - d.direction * ray.origin.dot(d.direction),
                                ),
                                w,
                            )
                        })
                    },
                    |_, _| e,
                )
            }
            Light::Constant(_) | Light::Envmap(_) => {
                chi2.run_weighted(|| next().map(|(ray, w)| (ray.dir, w)), |d| radiance_from(light, -d) * PI * 4.0)
            }
            _ => chi2.run_weighted(|| next().map(|(ray, w)| (ray.dir, w)), |d| intensity(light, d).unwrap()),
        };
        report(name, "aimed photons' power", &o, &mut failed);
    }
    assert!(failed.is_empty(), "{failed:?}");
}

/// Light from infinity's aimed photons started from the caustic pass's
/// low-discrepancy points (`photon_points`, as the pass gives them) carry
/// what the light sends, as those from random numbers do.
#[test]
fn aimed_photons_from_the_passs_points_carry_what_the_light_sends() {
    let lights: Vec<_> =
        lights().into_iter().filter(|(_, l)| matches!(l, Light::Constant(_) | Light::Envmap(_))).collect();
    let chi2 = Chi2 { cos_bins: 16, phi_bins: 32, samples: 300_000, tests: lights.len(), ..Chi2::default() };
    let mut failed = Vec::new();
    for (i, (name, light)) in lights.iter().enumerate() {
        let mut rng: Rng = stream(73, Domain::CausticPhotons, i as u64);
        let mut k = 0;
        let o = chi2.run_weighted(
            || {
                k += 1;
                let u = photon_points(73 + i as u64, k);
                light
                    .sample_le_towards_at(&Everywhere, u, &mut rng)
                    .map(|a| (a.ray.dir, sum(a.intensity) / a.pdf as f64))
            },
            |d| radiance_from(light, -d) * PI * 4.0,
        );
        report(name, "aimed photons' power from the pass's points", &o, &mut failed);
    }
    assert!(failed.is_empty(), "{failed:?}");
}

/// Why the pass's points: an environment map's aimed photons from them
/// cover the map's bright part and the aimed disk jointly evenly. Over 32
/// passes of 4,096 photons, how many come from the sun and start in one
/// quarter of the disk varies less than a tenth as much as with random
/// numbers (whose variance is the binomial one, p (1 - p) n).
#[test]
fn the_passs_points_spread_a_suns_photons_evenly_over_the_disk() {
    let light = Light::Envmap(Environment::new(envmap()));
    let n = 4096;
    let count = |start: &mut dyn FnMut(u64) -> Option<photonmap::light::Aimed>| -> f64 {
        (0..n)
            .filter(|&k| {
                start(k).is_some_and(|a| {
                    let d = a.ray.dir;
                    let f = Frame::from_normal(d);
                    let bright = radiance_from(&light, -d) > 10.0;
                    // Across the light, from the disk's centre (the box's).
                    let o = a.ray.origin - d * a.ray.origin.dot(d);
                    bright && o.dot(f.s) > 0.0 && o.dot(f.t) > 0.0
                })
            })
            .count() as f64
    };
    let variance = |counts: &[f64]| {
        let m = counts.iter().sum::<f64>() / counts.len() as f64;
        counts.iter().map(|c| (c - m).powi(2)).sum::<f64>() / (counts.len() - 1) as f64
    };
    let (mut quasi, mut random) = (Vec::new(), Vec::new());
    for pass in 0..32u64 {
        let mut rng: Rng = stream(pass, Domain::CausticPhotons, 0);
        quasi.push(count(&mut |k| light.sample_le_towards_at(&Everywhere, photon_points(pass, k), &mut rng)));
        let mut rng: Rng = stream(pass, Domain::CausticPhotons, 1);
        random.push(count(&mut |_| light.sample_le_towards(&Everywhere, &mut rng)));
    }
    let mean = quasi.iter().sum::<f64>() / quasi.len() as f64;
    let p = mean / n as f64;
    assert!(p > 0.05 && p < 0.25, "the sun's quarter holds {p} of the photons");
    let binomial = p * (1.0 - p) * n as f64;
    let (vq, vr) = (variance(&quasi), variance(&random));
    assert!(vr > 0.4 * binomial && vr < 2.0 * binomial, "random: {vr} against {binomial}");
    assert!(vq < 0.1 * vr, "quasi-random {vq} against random {vr}");
}

/// The caustic pass aims at glass spheres: a light at a point sends each
/// photon into one sphere's cone, with the power of the light's intensity
/// over the mixture of all cones' densities. Over directions, the photons'
/// power must be the light's intensity inside the cones and nothing
/// outside; across parallel light, the irradiance inside the spheres'
/// disks. Two overlapping spheres and two apart.
#[test]
fn caustic_photons_carry_what_the_light_sends_towards_the_targets() {
    let targets = [
        (Vec3::new(0.6, 0.4, -0.5), 0.35),
        (Vec3::new(0.4, 0.6, -0.8), 0.3),
        (Vec3::new(-0.7, -0.3, -0.6), 0.25),
        // In the spots' cone.
        (Vec3::new(0.35, -0.45, 1.2), 0.3),
    ];
    let lights = lights();
    let aimed: Vec<_> = lights.iter().filter(|(_, l)| l.is_delta()).collect();
    let chi2 = Chi2 { cos_bins: 24, phi_bins: 48, samples: 300_000, tests: aimed.len(), ..Chi2::default() };
    let mut failed = Vec::new();
    for (i, (name, light)) in aimed.iter().enumerate() {
        let scene = scene(vec![unplaced(light)], &targets);
        let aims = specular_targets(&scene);
        assert_eq!(aims.len(), targets.len());
        let placed = &scene.lights[0];
        let n = chi2.samples as u64;
        let mut k = 0;
        let mut next = || {
            k += 1;
            let mut rng = stream(81 + i as u64, Domain::CausticPhotons, k);
            emit(&scene, &aims, Pass::Caustic, n, &mut rng).1.map(|(ray, _, power)| (ray, sum(power) * n as f64))
        };
        let o = match placed {
            Light::Directional(d) => {
                // The plane through the origin across the light, a square
                // of side 4 on it.
                let f = Frame::from_normal(d.direction);
                let to_square = |p: Vec3| Vec2::new((p.dot(f.s) + 2.0) / 4.0, (p.dot(f.t) + 2.0) / 4.0);
                let inside = |u: f64, v: f64| {
                    let (x, y) = ((4.0 * u - 2.0) as f32, (4.0 * v - 2.0) as f32);
                    targets.iter().any(|&(c, r)| {
                        let (cx, cy) = (c.dot(f.s), c.dot(f.t));
                        (x - cx).powi(2) + (y - cy).powi(2) <= r * r
                    })
                };
                let e = sum(d.irradiance) * 16.0;
                chi2.run_weighted_square(
                    || next().map(|(ray, w)| (to_square(ray.origin), w)),
                    |u, v| if inside(u, v) { e } else { 0.0 },
                )
            }
            _ => {
                let at = placed.bounds().unwrap().0;
                let in_a_cone = |d: Vec3| {
                    targets.iter().any(|&(c, r)| {
                        let to = c - at;
                        d.dot(to.normalize()) >= (1.0 - r * r / to.length_squared()).sqrt()
                    })
                };
                chi2.run_weighted(
                    || next().map(|(ray, w)| (ray.dir, w)),
                    |d| if in_a_cone(d) { intensity(placed, d).unwrap() } else { 0.0 },
                )
            }
        };
        report(name, "caustic photons' power", &o, &mut failed);
        // Every light sends some of its power at the targets: the test
        // bins something.
        assert!(o.pdf_mass > 0.0 && o.dof >= 20, "{name}: {} sent at the targets, {} cells", o.pdf_mass, o.dof);
    }
    assert!(failed.is_empty(), "{failed:?}");
}

/// The light hierarchy's choices against its own chances, at three
/// points among 50 disk lights and 20 triangles of random place, size,
/// facing and radiance, three point lights and a sky: which light it
/// chooses (the chance of none too: a descent can end at a light that
/// sends nothing there), and the direction of the shadow ray that light
/// then samples, against the density multiple importance sampling weighs
/// it by, Σ over lights of the chance times the light's own density.
#[test]
fn the_light_hierarchy_chooses_lights_by_its_own_chances() {
    use photonmap::light::LightSampler;
    let mut rng = stream(91, Domain::Camera, 0);
    let mut lights = Vec::new();
    for i in 0..70 {
        let (u, v) = (next_2d(&mut rng), next_2d(&mut rng));
        let center = Vec3::new(u.x * 8.0 - 4.0, u.y * 8.0 - 4.0, 1.0 + 3.0 * v.x);
        let normal = uniform_cone(next_2d(&mut rng), -1.0).normalize();
        let radiance = Color::new(1.0 + v.y * 4.0, 1.0, 2.0);
        let surface = if i < 50 {
            Emitting::Disk(Disk { center, normal, radius: 0.05 + 0.3 * v.y })
        } else {
            let f = Frame::from_normal(normal);
            let s = 0.1 + 0.4 * v.y;
            Emitting::Triangle(Triangle::new(center, center + f.s * s, center + f.t * s))
        };
        lights.push(Light::Area(AreaLight::new(surface, radiance, i)));
    }
    for k in 0..3 {
        let position = Vec3::new(k as f32 * 2.0 - 2.0, 1.0, 2.5);
        lights.push(Light::Point(PointLight {
            position,
            intensity: Color::splat(3.0),
            falloff: 2.0,
            dead_distance: 0.0,
        }));
    }
    let mut sky = Light::Constant(Constant::new(Color::splat(0.2)));
    sky.place(Vec3::splat(-5.0), Vec3::splat(5.0));
    lights.push(sky);
    let tree = LightSampler::new(&lights, 10.0);
    let points = [
        (Vec3::new(0.0, 0.0, 0.0), Vec3::Z),
        (Vec3::new(1.5, -2.0, 2.0), Vec3::new(0.3, 0.2, 1.0).normalize()),
        (Vec3::new(-3.0, 2.5, 3.5), Vec3::new(-1.0, 0.0, 0.2).normalize()),
    ];
    let tests = 2 * points.len();
    let mut failed = Vec::new();
    for (j, (p, n)) in points.into_iter().enumerate() {
        let chi2 = Chi2 { samples: 300_000, cos_bins: 16, phi_bins: 32, tests, ..Chi2::default() };
        let mut rng = stream(92, Domain::Camera, j as u64);
        let mut observed = vec![0f64; lights.len() + 1];
        for _ in 0..chi2.samples {
            match tree.sample(p, n, rand::RngExt::random::<f64>(&mut rng)) {
                Some((i, _)) => observed[i] += 1.0,
                None => observed[lights.len()] += 1.0,
            }
        }
        let chances: Vec<f64> = (0..lights.len()).map(|i| tree.pmf(p, n, i) as f64).collect();
        let total: f64 = chances.iter().sum();
        assert!(total <= 1.0 + 1e-4 && total > 0.3, "{p}: chances sum to {total}");
        let mut expected: Vec<f64> = chances.iter().map(|c| c * chi2.samples as f64).collect();
        expected.push((1.0 - total).max(0.0) * chi2.samples as f64);
        let o = chi2.pearson(&observed, &expected, total);
        report("light hierarchy", &format!("lights chosen at {p:.2}"), &o, &mut failed);
        // The shadow rays' directions, delta lights aside (no density).
        let o = chi2.run(
            || {
                let (i, _) = tree.sample(p, n, rand::RngExt::random::<f64>(&mut rng))?;
                if lights[i].is_delta() {
                    return None;
                }
                lights[i].sample_li(p, n, next_2d(&mut rng)).map(|inc| inc.dir)
            },
            |w| {
                let w = w.normalize();
                lights
                    .iter()
                    .zip(&chances)
                    .map(|(l, &c)| if c > 0.0 { c * l.pdf_li(p, n, w) as f64 } else { 0.0 })
                    .sum()
            },
        );
        report("light hierarchy", &format!("shadow-ray directions at {p:.2}"), &o, &mut failed);
    }
    assert!(failed.is_empty(), "{failed:?}");
}
