//! The photon pass alone, for profilers: `cargo run --release --example
//! pass_profile -- [global|caustic] [photons] [repeats]` (1 thread unless
//! RAYON_NUM_THREADS says otherwise).
use photonmap::photon::trace::{trace_pass, Pass};
use photonmap::scene::{Eye, Scene};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let pass = match args.get(1).map(String::as_str) {
        Some("caustic") => Pass::Caustic,
        _ => Pass::Global,
    };
    let n: u64 = args.get(2).and_then(|s| s.parse::<f64>().ok()).unwrap_or(1e6) as u64;
    let repeats: u32 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(3);
    let scene = Scene::tncg15(Eye::One);
    // Minor page faults and system time so far (Linux), from /proc.
    let usage = || -> (u64, u64) {
        let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
        let f: Vec<u64> =
            stat.rsplit(')').next().unwrap_or("").split_whitespace().map(|x| x.parse().unwrap_or(0)).collect();
        // Fields 10 (minflt) and 15 (stime) of proc(5); the list starts at field 3.
        (f.get(7).copied().unwrap_or(0), f.get(12).copied().unwrap_or(0))
    };
    for _ in 0..repeats {
        let (f0, s0) = usage();
        let t = Instant::now();
        let out = trace_pass(&scene, pass, n, 1, &|_| {});
        let dt = t.elapsed().as_secs_f64();
        let (f1, s1) = usage();
        println!("  {} minor faults, {} ms system time", f1 - f0, (s1 - s0) * 10);
        println!(
            "{pass:?}: {n} photons, {} rays, {} stored: {:.3} s, {:.0} ns per photon, {:.1} ns per ray",
            out.rays,
            out.photons.len(),
            dt,
            dt / n as f64 * 1e9,
            dt / out.rays as f64 * 1e9
        );
    }
}
