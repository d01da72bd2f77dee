//! The renderer's phases on the default scene, one group each:
//! `cargo bench --bench phases` (figures in notes/performance.md).

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use photonmap::photon::irradiance_cache::IrradianceCache;
use photonmap::photon::map::{PhotonMap, Scratch};
use photonmap::photon::trace::{trace_pass, Pass};
use photonmap::progress::Mode;
use photonmap::render::{render, GLOBAL_GRID_CELL};
use photonmap::scene::{Eye, Scene};
use photonmap::settings::{cache_stride, Settings, GLOBAL_RADIUS_FRACTION};
use std::hint::black_box;

fn photon_pass(c: &mut Criterion) {
    let scene = Scene::tncg15(Eye::One);
    let mut g = c.benchmark_group("photon_pass");
    g.sample_size(10);
    for (name, pass) in [("global", Pass::Global), ("caustic", Pass::Caustic)] {
        g.throughput(Throughput::Elements(100_000));
        g.bench_function(name, |b| b.iter(|| black_box(trace_pass(&scene, pass, 100_000, 1, &|_| {}).photons.len())));
    }
    g.finish();
}

fn kd_tree_build(c: &mut Criterion) {
    let scene = Scene::tncg15(Eye::One);
    // About one million stored photons (200k emitted, ~5 diffuse hits each).
    let photons = trace_pass(&scene, Pass::Global, 200_000, 1, &|_| {}).photons;
    let mut g = c.benchmark_group("kd_tree_build");
    g.sample_size(10);
    g.throughput(Throughput::Elements(photons.len() as u64));
    // A fixed name: the stored count moves with any change to photon paths,
    // and a name carrying it would leave the committed baseline behind.
    g.bench_function("200k_emitted", |b| {
        b.iter_batched(|| photons.clone(), |p| black_box(PhotonMap::build(p).len()), BatchSize::LargeInput)
    });
    // The global map as a render builds it (a grid sized for the cache's
    // searches, no tree where the grid serves them all), and the
    // irradiance cache computed from it.
    let r_global = GLOBAL_RADIUS_FRACTION * scene.diagonal();
    g.bench_function("global_map_and_cache_200k_emitted", |b| {
        b.iter_batched(
            || photons.clone(),
            |p| {
                let map = PhotonMap::build_for_photon_lookups(p, r_global * GLOBAL_GRID_CELL);
                let stride = cache_stride(100, map.len());
                black_box(IrradianceCache::build(&map, stride, 100, r_global).len())
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

fn radiance_queries(c: &mut Criterion) {
    let scene = Scene::tncg15(Eye::One);
    let caustic_photons = trace_pass(&scene, Pass::Caustic, 1_000_000, 1, &|_| {}).photons;
    let r = 0.01 * scene.diagonal();
    // The tree alone, and the map as a render builds it (the tree behind
    // a grid of cells); the same estimates.
    let caustic = PhotonMap::build(caustic_photons.clone());
    let caustic_grid = PhotonMap::build_with_grid(caustic_photons, Some(r));
    let global = PhotonMap::build(trace_pass(&scene, Pass::Global, 200_000, 1, &|_| {}).photons);
    let cache = IrradianceCache::build(&global, 4, 100, 0.05 * scene.diagonal());
    // Query points: a line of floor points through the glass sphere's caustic.
    let queries: Vec<glam::Vec3> =
        (0..1000).map(|i| glam::Vec3::new(8.0 + 4.0 * i as f32 / 1000.0, -2.5, -5.0)).collect();
    let n = glam::Vec3::Z;
    let mut g = c.benchmark_group("radiance_queries");
    g.throughput(Throughput::Elements(queries.len() as u64));
    for (name, map) in [("caustic_cone_k100", &caustic), ("caustic_cone_k100_grid", &caustic_grid)] {
        g.bench_function(name, |b| {
            let mut s = Scratch::default();
            b.iter(|| queries.iter().map(|&x| map.radiance_cone(x, n, glam::Vec3::ONE, 100, r, &mut s).x).sum::<f32>())
        });
    }
    // The caustic estimates of a render: at the first diffuse hits of
    // 200 x 200 camera rays, in row order.
    let hits = scene.diffuse_hits(200, 200);
    g.throughput(Throughput::Elements(hits.len() as u64));
    g.bench_function("caustic_cone_k100_grid_pixels", |b| {
        let mut s = Scratch::default();
        b.iter(|| {
            hits.iter().map(|&(x, n)| caustic_grid.radiance_cone(x, n, glam::Vec3::ONE, 100, r, &mut s).x).sum::<f32>()
        })
    });
    g.throughput(Throughput::Elements(queries.len() as u64));
    g.bench_function("irradiance_cache_lookup", |b| {
        b.iter(|| queries.iter().map(|&x| cache.lookup(x, n).x).sum::<f32>())
    });
    g.finish();
}

fn full_render(c: &mut Criterion) {
    let scene = Scene::tncg15(Eye::One);
    let settings =
        Settings { photons: 100_000, caustic_photons: 100_000, width: 100, height: 100, ..Settings::default() };
    let mut g = c.benchmark_group("full_render");
    g.sample_size(10);
    g.bench_function("100x100_1e5_photons", |b| b.iter(|| black_box(render(&scene, &settings, Mode::Quiet).0.mean())));
    g.finish();
}

/// What skipping saves: a black room (no photon maps needed) and the
/// default room, each rendered with the skips on and forced off.
fn skips(c: &mut Criterion) {
    let mut black = Scene::tncg15_parts(Eye::One);
    for m in &mut black.materials {
        if let photonmap::material::Material::Lambertian { rho } = m {
            *rho = glam::Vec3::ZERO;
        }
    }
    let scenes = [("black_room", Scene::from_parts(black)), ("default_room", Scene::tncg15(Eye::One))];
    let mut g = c.benchmark_group("skips");
    g.sample_size(10);
    for (name, scene) in &scenes {
        for skip in [true, false] {
            let settings = Settings {
                photons: 200_000,
                caustic_photons: 200_000,
                width: 64,
                height: 64,
                skip,
                ..Settings::default()
            };
            let label = format!("{name}/{}", if skip { "skip" } else { "no_skip" });
            g.bench_function(label, |b| b.iter(|| black_box(render(scene, &settings, Mode::Quiet).0.mean())));
        }
    }
    // A pixel's samples sharing their caustic estimate, and each making its
    // own: pixels small enough for the samples to land within reach (at
    // 160 x 160 they rarely do), one gather ray to keep it short.
    let room = Scene::tncg15(Eye::One);
    for reuse in [photonmap::settings::CAUSTIC_REUSE, 0.0] {
        let settings = Settings {
            photons: 100_000,
            caustic_photons: 200_000,
            width: 400,
            height: 400,
            gather_rays: 1,
            caustic_reuse: reuse,
            ..Settings::default()
        };
        let label = format!("caustic_reuse/{}", if reuse > 0.0 { "skip" } else { "no_skip" });
        g.bench_function(label, |b| b.iter(|| black_box(render(&room, &settings, Mode::Quiet).0.mean())));
    }
    // Caustic lookups with and without the map's grid: a glass ball on
    // a wide floor under the sun, whose caustic map is empty in most places.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/glass-sun.toml");
    let glass_only = Scene::from_parts(photonmap::scene::file::load(&path).unwrap().parts);
    let points = glass_only.diffuse_hits(64, 48);
    let photons = trace_pass(&glass_only, Pass::Caustic, 200_000, 1, &|_| {}).photons;
    let r = Settings::default().r_caustic(glass_only.diagonal());
    for skip in [true, false] {
        let map = PhotonMap::build_with_grid(photons.clone(), Some(r));
        let map = if skip { map } else { map.without_grid() };
        let label = format!("glass_sun_caustic_lookups/{}", if skip { "skip" } else { "no_skip" });
        g.throughput(Throughput::Elements(points.len() as u64));
        g.bench_function(label, |b| {
            let mut scratch = Scratch::default();
            b.iter(|| {
                points
                    .iter()
                    .map(|&(x, n)| map.radiance_cone(x, n, glam::Vec3::splat(0.8), 100, r, &mut scratch).x)
                    .sum::<f32>()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, photon_pass, kd_tree_build, radiance_queries, full_render, skips);
criterion_main!(benches);
