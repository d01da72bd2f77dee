//! The memory a render needs at its peak, as `Settings::estimated_peak_bytes`
//! predicts it (a render that would not fit is refused before it
//! allocates), against the peak resident size of the `photonmap` program
//! measured as it renders: Linux's high-water mark of its resident memory
//! (`VmHWM` in /proc/PID/status), read until it exits.

mod common;
use common::scratch_dir;
use photonmap::settings::Settings;
use std::process::{Command, Stdio};
use std::time::Duration;

/// The high-water mark of a running process's resident memory, in bytes.
fn high_water(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    Some(line.split_whitespace().nth(1)?.parse::<u64>().ok()? * 1024)
}

/// The peak resident size of `photonmap ARGS`: the largest high-water mark
/// read while it runs (the mark only grows, and the peak, at the map
/// build, comes well before the camera pass and the output).
fn peak_of(args: &[&str]) -> u64 {
    let mut child = Command::new(env!("CARGO_BIN_EXE_photonmap"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run photonmap");
    let mut peak = 0;
    while child.try_wait().unwrap().is_none() {
        peak = peak.max(high_water(child.id()).unwrap_or(0));
        std::thread::sleep(Duration::from_millis(2));
    }
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    peak
}

/// Within 10% at two mixes of global and caustic photons.
#[test]
fn the_estimate_matches_the_measured_peaks() {
    if high_water(std::process::id()).is_none() {
        eprintln!("no /proc/PID/status VmHWM here: nothing to measure");
        return;
    }
    let dir = scratch_dir("memory-peaks");
    let out = dir.join("peak.exr");
    let mut said = Vec::new();
    for (photons, caustic) in [(300_000u64, 300_000u64), (600_000, 100_000)] {
        let (p, c) = (photons.to_string(), caustic.to_string());
        let args = ["-q", "--threads", "2", "--width", "100", "--height", "100", "--spp", "1"];
        let peak = peak_of(&[&args[..], &["--photons", &p, "--caustic-photons", &c, out.to_str().unwrap()]].concat());
        let settings =
            Settings { photons, caustic_photons: caustic, width: 100, height: 100, spp: 1, ..Settings::default() };
        let ratio = settings.estimated_peak_bytes(false) as f64 / peak as f64;
        said.push(format!("{photons} + {caustic}: peak {:.1} MB, estimate / peak {ratio:.3}", peak as f64 / 1e6));
        assert!((0.9..1.1).contains(&ratio), "{}", said.join("; "));
    }
    println!("{}", said.join("\n"));
}
