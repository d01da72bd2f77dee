//! The memory a render needs at its peak, as `Settings::estimated_peak_bytes`
//! predicts it (a render that would not fit is refused before it
//! allocates), against the peak resident size of the `photonmap` program:
//! the kernel's high-water mark of its resident memory, which `wait4`
//! returns when it exits (`ru_maxrss`). Polling `/proc/PID/status` while it
//! ran missed the peak on a loaded machine, where the poller could sleep
//! past the child's whole map build and exit.

mod common;
use common::scratch_dir;
use photonmap::settings::Settings;
use std::io::Read;
use std::process::{Command, Stdio};

/// The peak resident size of `photonmap ARGS`, in bytes, from the rusage
/// that reaping it returns.
#[cfg(target_os = "linux")]
#[allow(clippy::zombie_processes)] // reaped by wait4, not Child::wait
fn peak_of(args: &[&str]) -> u64 {
    let mut child = Command::new(env!("CARGO_BIN_EXE_photonmap"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run photonmap");
    let mut stderr = String::new();
    child.stderr.take().expect("piped stderr").read_to_string(&mut stderr).unwrap();
    let (mut status, mut usage) = (0, unsafe { std::mem::zeroed::<libc::rusage>() });
    // SAFETY: the child is ours and not yet reaped; both pointers are to
    // live locals of the types wait4 writes.
    let pid = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as libc::pid_t, "wait4: {}", std::io::Error::last_os_error());
    assert!(libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0, "{stderr}");
    // Linux gives ru_maxrss in kilobytes.
    usage.ru_maxrss as u64 * 1024
}

/// Within 10% at two mixes of global and caustic photons.
#[cfg(target_os = "linux")]
#[test]
fn the_estimate_matches_the_measured_peaks() {
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
