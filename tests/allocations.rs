//! Hot loops allocate nothing: a counting global allocator shows that the
//! photon pass allocates per block of photons (not per photon) and the
//! camera pass per row of pixels (not per ray). One test, so that no other
//! test's allocations run in between, and on a one-thread pool: with more
//! threads, how often rayon splits the work (and so how many per-split
//! buffers exist) depends on stealing, and the counts would be noise.

use photonmap::photon::trace::{trace_pass, Pass};
use photonmap::progress::Mode;
use photonmap::render::render;
use photonmap::scene::{Eye, Scene};
use photonmap::settings::Settings;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn count<T>(f: impl FnOnce() -> T) -> (T, u64) {
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let out = f();
    (out, ALLOCATIONS.load(Ordering::Relaxed) - before)
}

#[test]
fn hot_loops_do_not_allocate_per_photon_or_per_ray() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(check_counts);
}

fn check_counts() {
    let scene = Scene::tncg15(Eye::One);
    // Photon pass: 4x the photons, and the extra allocations stay at a few
    // per 4096-photon block (the block's photon buffer growing).
    for pass in [Pass::Global, Pass::Caustic] {
        let (small, a_small) = count(|| trace_pass(&scene, pass, 40_960, 1, &|_| {}));
        let (large, a_large) = count(|| trace_pass(&scene, pass, 163_840, 1, &|_| {}));
        let extra_rays = large.rays - small.rays;
        let per_ray = (a_large - a_small) as f64 / extra_rays as f64;
        eprintln!("{pass:?} pass: {a_small} / {a_large} allocations for {} / {} rays", small.rays, large.rays);
        assert!(per_ray < 1e-3, "{pass:?} pass: {per_ray:.5} allocations per ray");
    }
    // Camera pass: 4x the pixels, and the extra allocations stay at a few
    // per row, far below one per ray.
    let settings =
        |size| Settings { photons: 20_000, caustic_photons: 20_000, width: size, height: size, ..Settings::default() };
    let ((_, small), a_small) = count(|| render(&scene, &settings(32), Mode::Quiet));
    let ((_, large), a_large) = count(|| render(&scene, &settings(64), Mode::Quiet));
    let extra_rays = large.camera.rays - small.camera.rays;
    let per_ray = (a_large - a_small) as f64 / extra_rays as f64;
    eprintln!("camera pass: {a_small} / {a_large} allocations for {} / {} rays", small.camera.rays, large.camera.rays);
    assert!(per_ray < 1e-2, "camera pass: {per_ray:.5} allocations per ray");
    let per_row = (a_large - a_small) as f64 / 32.0;
    assert!(per_row < 3.0, "camera pass: {per_row:.1} allocations per extra row of pixels");
}
