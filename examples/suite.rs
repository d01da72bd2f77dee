//! The scene suite, run and scored: `cargo run --release --example suite`.
//!
//! For every scene of scenes/suite/suite.toml: photonmap's default render
//! (the scene file's camera and size, default settings), timed from
//! loading the scene to the finished image, and a 60-second progressive
//! render; each scored against the scene's independent reference (the
//! reference's own noise subtracted in quadrature). Where Mitsuba 3 is
//! installed (MITSUBA_PYTHON, a Python with mitsuba 3.9.1; see
//! tools/mitsuba_reference.py), its path tracer renders the exported scene
//! for the same wall times and is scored the same way.
//!
//! Writes notes/suite.md (the table), notes/suite.csv and one picture per
//! scene in notes/suite/ (photonmap | reference | signed difference).
//!
//! Options: `--only NAME` (repeatable), `--no-mitsuba`, `--no-progressive`,
//! `--seconds S` (the progressive budget, default 60), `--out DIR` (where
//! the notes go; default notes/). `--help` prints these; an unknown option
//! or an `--only` name not in suite.toml is refused before anything runs.

use photonmap::film::{Film, ToneMap};
use photonmap::metrics::{box_down, diff_rgb8, Comparison};
use photonmap::output::{read_exr, write, write_rgb8_image};
use photonmap::progress::Mode;
use photonmap::render::{render, render_progressive, Budget};
use photonmap::scene::Scene;
use photonmap::settings::{
    default_global_photons, default_vertex_rays, progressive_caustics, Settings, DEFAULT, PROGRESSIVE_CAUSTIC_PHOTONS,
    PROGRESSIVE_K_CAUSTIC, PROGRESSIVE_PHOTONS, PROGRESSIVE_SPP,
};
use photonmap::suite::SuiteScene;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const USAGE: &str = "usage: cargo run --release --example suite -- [--only NAME]... \
[--no-mitsuba] [--no-progressive] [--seconds S] [--out DIR]";

/// The first argument that is not one of the options (or lacks its value),
/// so that a typo, or `--help`, does not start the whole suite.
fn unknown_option(args: &[String]) -> Option<String> {
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--no-mitsuba" | "--no-progressive" => {}
            "--only" | "--seconds" | "--out" => {
                if it.next().is_none() {
                    return Some(a.clone());
                }
            }
            _ => return Some(a.clone()),
        }
    }
    None
}

/// One render scored.
#[derive(Clone)]
struct Scored {
    seconds: f64,
    /// Samples per pixel (Mitsuba) or passes (progressive).
    count: u64,
    c: Comparison,
    rmse: f64,
    caustic_rmse: f64,
}

struct Row {
    name: String,
    spp: Option<u64>,
    noise: (Option<f64>, Option<f64>),
    classic: Scored,
    progressive: Option<Scored>,
    mitsuba_classic: Option<Scored>,
    mitsuba_progressive: Option<Scored>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if let Some(bad) = unknown_option(&args[1..]) {
        if bad == "--help" || bad == "-h" {
            println!("{USAGE}");
            return Ok(());
        }
        eprintln!("suite: unknown option or missing value: {bad}\n{USAGE}");
        std::process::exit(2);
    }
    let flag = |f: &str| args.iter().any(|a| a == f);
    let value = |f: &str| args.windows(2).filter(|w| w[0] == f).map(|w| w[1].clone()).collect::<Vec<_>>();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out_dir = value("--out").first().map(PathBuf::from).unwrap_or_else(|| root.join("notes"));
    let seconds: f64 = value("--seconds").first().map_or(Ok(60.0), |s| s.parse())?;
    let only = value("--only");
    let mitsuba = (!flag("--no-mitsuba")).then(mitsuba_python).flatten();
    photonmap::scene::procedural::write_suite_meshes(&root.join("scenes/suite/meshes"), true)?;
    let suite = photonmap::suite::load(&root.join("scenes/suite"))?;
    if let Some(name) = only.iter().find(|n| !suite.iter().any(|s| &s.name == *n)) {
        let names: Vec<&str> = suite.iter().map(|s| s.name.as_str()).collect();
        eprintln!("suite: --only {name}: no such scene (scenes/suite/suite.toml has {})", names.join(", "));
        std::process::exit(2);
    }
    let work = std::env::temp_dir().join(format!("photonmap-suite-{}", std::process::id()));
    std::fs::create_dir_all(&work)?;
    std::fs::create_dir_all(out_dir.join("suite"))?;
    let mut rows = Vec::new();
    for s in suite.iter().filter(|s| only.is_empty() || only.contains(&s.name)) {
        let scoring = s.scoring()?;
        let (reference, info) = (&scoring.reference, &scoring.info);
        let score = |film: &Film, seconds: f64, count: u64| -> Result<Scored, String> {
            let sc = scoring.score(film)?;
            Ok(Scored { seconds, count, c: sc.comparison, rmse: sc.rmse, caustic_rmse: sc.caustic_rmse })
        };
        // The default command: load, render.
        let t = Instant::now();
        let file = photonmap::scene::file::load(&s.scene)?;
        let n = file.rays_per_pixel_edge;
        let scene = Scene::from_parts(file.parts);
        let media = scene.media().is_some();
        let (gather_rays, shadow_rays) = default_vertex_rays(DEFAULT.method, media);
        let settings = Settings {
            photons: default_global_photons(DEFAULT.photons, media),
            gather_rays,
            shadow_rays,
            spp: n * n,
            width: scene.camera.width,
            height: scene.camera.height,
            ..Settings::default()
        };
        let (film, _) = render(&scene, &settings, Mode::Quiet);
        let classic = score(&film, t.elapsed().as_secs_f64(), 1)?;
        write(&work.join(format!("{}.exr", s.name)), &film, ToneMap::Display, 1.0)?;
        eprintln!(
            "{:<16} default     {:>7.1} s  rmse {:.5}  caustic {:.5}",
            s.name, classic.seconds, classic.rmse, classic.caustic_rmse
        );
        picture(&out_dir.join("suite").join(format!("{}.png", s.name)), &film, reference, classic.c.factor)?;
        let progressive = if flag("--no-progressive") {
            None
        } else {
            let t = Instant::now();
            let (caustic_photons, k_caustic) = progressive_caustics(scene.media().is_some());
            let photons = default_global_photons(PROGRESSIVE_PHOTONS, media);
            let p = Settings { photons, caustic_photons, k_caustic, spp: PROGRESSIVE_SPP, ..settings };
            let load = std::time::Duration::ZERO;
            let (film, stats) = render_progressive(&scene, &p, Budget::seconds(seconds - load.as_secs_f64()), |_| {});
            let scored = score(&film, t.elapsed().as_secs_f64(), stats.passes as u64)?;
            eprintln!(
                "{:<16} progressive {:>7.1} s  rmse {:.5}  caustic {:.5}  ({} passes)",
                s.name, scored.seconds, scored.rmse, scored.caustic_rmse, stats.passes
            );
            Some(scored)
        };
        let (mut mitsuba_classic, mut mitsuba_progressive) = (None, None);
        if let Some(py) = &mitsuba {
            let xml = work.join(format!("{}.xml", s.name));
            let file = photonmap::scene::file::load(&s.scene)?;
            let mesh_dir = format!("{}-meshes", s.name);
            // The reference's placement: Mitsuba's renders converge to it.
            let placement = match s.mitsuba_placement {
                Some((origin, scale)) => photonmap::export::mitsuba::Placement::new(origin, scale)?,
                None => photonmap::export::mitsuba::Placement::at_eye(&file.parts.camera),
            };
            let exported =
                photonmap::export::mitsuba::to_mitsuba(&file.parts, Some(&file.origins), &mesh_dir, placement)
                    .map_err(|r| r.describe(Some(&file.origins)))?;
            std::fs::create_dir_all(work.join(&mesh_dir))?;
            for (name, bytes) in &exported.meshes {
                std::fs::write(work.join(name), bytes)?;
            }
            std::fs::write(&xml, &exported.xml)?;
            let mut budgets = vec![(classic.seconds, &mut mitsuba_classic)];
            if let Some(p) = &progressive {
                budgets.push((p.seconds, &mut mitsuba_progressive));
            }
            for (budget, slot) in budgets {
                let exr = work.join(format!("{}-mitsuba-{budget:.0}.exr", s.name));
                let (w, h) = (scene.camera.width.to_string(), scene.camera.height.to_string());
                let o = Command::new(py)
                    .arg(root.join("tools/mitsuba_equal_time.py"))
                    .arg(&xml)
                    .arg(format!("{budget}"))
                    .arg(&exr)
                    .args(["--width", &w, "--height", &h])
                    .output()?;
                if !o.status.success() {
                    let err = String::from_utf8_lossy(&o.stderr);
                    // Dr.Jit's llvm backend finds the system's libLLVM, which
                    // may be older than the 16 it needs; it then stops here,
                    // and its error is a page of LLVM's selection DAG.
                    let said = if err.contains("LLVM ERROR") {
                        format!(
                            "{} (Mitsuba's llvm variant needs libLLVM 16 or newer: point DRJIT_LIBLLVM_PATH \
                             at its .so, as tools/mitsuba_reference.py explains)",
                            err.lines().next().unwrap_or_default()
                        )
                    } else {
                        err.into_owned()
                    };
                    return Err(format!("Mitsuba on {}: {said}", s.name).into());
                }
                let v: serde_json::Value = serde_json::from_slice(&o.stdout)?;
                let scored =
                    score(&read_exr(&exr)?, v["seconds"].as_f64().unwrap_or(budget), v["spp"].as_u64().unwrap_or(0))?;
                eprintln!(
                    "{:<16} mitsuba     {:>7.1} s  rmse {:.5}  caustic {:.5}  ({} spp)",
                    s.name, scored.seconds, scored.rmse, scored.caustic_rmse, scored.count
                );
                *slot = Some(scored);
            }
        }
        rows.push(Row {
            name: s.name.clone(),
            spp: info.spp,
            noise: (info.noise, info.caustic_noise),
            classic,
            progressive,
            mitsuba_classic,
            mitsuba_progressive,
        });
    }
    let _ = std::fs::remove_dir_all(&work);
    std::fs::write(out_dir.join("suite.md"), report(&rows, &suite, seconds))?;
    std::fs::write(out_dir.join("suite.csv"), csv(&rows))?;
    eprintln!("wrote {}", out_dir.join("suite.md").display());
    Ok(())
}

/// A Python that imports mitsuba: MITSUBA_PYTHON, else python3.
fn mitsuba_python() -> Option<PathBuf> {
    let py = std::env::var_os("MITSUBA_PYTHON").map(PathBuf::from).unwrap_or_else(|| "python3".into());
    let ok = Command::new(&py).args(["-c", "import mitsuba"]).output().is_ok_and(|o| o.status.success());
    ok.then_some(py)
}

/// photonmap (reduced to the reference's size) | reference | signed
/// difference, side by side; both images under the reference's exposure.
fn picture(path: &Path, film: &Film, reference: &Film, factor: u32) -> Result<(), Box<dyn std::error::Error>> {
    let down = box_down(film, factor);
    let (w, h) = (reference.width, reference.height);
    let scale = reference.display_scale();
    let shown = |f: &Film| Film {
        width: w,
        height: h,
        pixels: f.pixels.iter().map(|c| *c * (scale / f.display_scale())).collect(),
    };
    let a = shown(&down).to_rgb8(ToneMap::Display, 1.0);
    let b = reference.to_rgb8(ToneMap::Display, 1.0);
    let (d, _) = diff_rgb8(&down, reference, None);
    let gap = 4;
    let total = 3 * w + 2 * gap;
    let mut rgb = vec![255u8; (total * h * 3) as usize];
    for (k, img) in [a, b, d].iter().enumerate() {
        for y in 0..h {
            for x in 0..w {
                let src = ((y * w + x) * 3) as usize;
                let dst = ((y * total + k as u32 * (w + gap) + x) * 3) as usize;
                rgb[dst..dst + 3].copy_from_slice(&img[src..src + 3]);
            }
        }
    }
    write_rgb8_image(path, total, h, rgb)?;
    Ok(())
}

fn ratio(peer: Option<&Scored>, ours: f64, pick: impl Fn(&Scored) -> f64) -> String {
    match peer {
        Some(p) if ours > 0.0 => format!("{:.1}x", pick(p) / ours),
        _ => "—".into(),
    }
}

fn report(rows: &[Row], suite: &[SuiteScene], seconds: f64) -> String {
    let commit = Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let threads = rayon::current_num_threads();
    let mut s = String::new();
    let _ = writeln!(s, "# The scene suite\n");
    let _ = writeln!(
        s,
        "`cargo run --release --example suite` at commit {commit}, on {cpu} ({threads} threads). Every scene is \
         scored against its independent reference (Mitsuba 3's path tracer on the exported scene, 200 x 200; \
         tests/data/suite/), with the metric of `photonmap compare`: RMSE over the whole image and the caustic \
         window (scenes/suite/suite.toml), each less the reference's own noise in quadrature; bias is the mean's \
         relative difference. *Default*: photonmap's default settings, timed from loading the scene to the \
         finished image. *Progressive*: {seconds:.0} s of progressive passes ({} global and {} caustic photons, caustic k {} (in a scene with media as many \
         caustic photons as global ones, k 100), and {} spp a pass). \
         *Mitsuba*: its path tracer at the same wall time, loading included; *ratio*: Mitsuba's error over \
         photonmap's.\n",
        PROGRESSIVE_PHOTONS, PROGRESSIVE_CAUSTIC_PHOTONS, PROGRESSIVE_K_CAUSTIC, PROGRESSIVE_SPP
    );
    let _ = writeln!(s, "| scene | ref spp | ref noise (whole / caustic) | default: time | bias | caustic bias | RMSE | caustic RMSE | speckles | Mitsuba RMSE / caustic (spp) | ratio | caustic ratio |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let c = &r.classic;
        let m = r.mitsuba_classic.as_ref();
        let _ = writeln!(
            s,
            "| {} | {} | {} / {} | {:.1} s | {:+.2}% | {:+.2}% | {:.5} | {:.4} | {} | {} | {} | {} |",
            r.name,
            r.spp.map_or("—".into(), |v| v.to_string()),
            r.noise.0.map_or("—".into(), |v| format!("{v:.5}")),
            r.noise.1.map_or("—".into(), |v| format!("{v:.4}")),
            c.seconds,
            100.0 * c.c.whole.bias(),
            100.0 * c.c.windows[0].1.bias(),
            c.rmse,
            c.caustic_rmse,
            c.c.speckles,
            m.map_or("—".into(), |m| format!("{:.5} / {:.4} ({})", m.rmse, m.caustic_rmse, m.count)),
            ratio(m, c.rmse, |p| p.rmse),
            ratio(m, c.caustic_rmse, |p| p.caustic_rmse),
        );
    }
    if rows.iter().any(|r| r.progressive.is_some()) {
        let _ = writeln!(s, "\n| scene | progressive: time (passes) | bias | caustic bias | RMSE | caustic RMSE | Mitsuba RMSE / caustic (spp) | ratio | caustic ratio |");
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
        for r in rows {
            let Some(p) = &r.progressive else { continue };
            let m = r.mitsuba_progressive.as_ref();
            let _ = writeln!(
                s,
                "| {} | {:.1} s ({}) | {:+.2}% | {:+.2}% | {:.5} | {:.4} | {} | {} | {} |",
                r.name,
                p.seconds,
                p.count,
                100.0 * p.c.whole.bias(),
                100.0 * p.c.windows[0].1.bias(),
                p.rmse,
                p.caustic_rmse,
                m.map_or("—".into(), |m| format!("{:.5} / {:.4} ({})", m.rmse, m.caustic_rmse, m.count)),
                ratio(m, p.rmse, |q| q.rmse),
                ratio(m, p.caustic_rmse, |q| q.caustic_rmse),
            );
        }
    }
    let _ = writeln!(s, "\n{}", below_noise(rows, seconds));
    let cropped: Vec<String> = suite
        .iter()
        .filter(|x| x.caustic_reference.is_some() && rows.iter().any(|r| r.name == x.name))
        .map(|x| {
            let json = x.caustic_reference.as_ref().map(|p| p.with_extension("json"));
            let spp = json
                .and_then(|j| std::fs::read_to_string(j).ok())
                .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
                .and_then(|v| v["spp"].as_u64());
            format!("{} ({} spp)", x.name, spp.map_or("—".into(), |v| v.to_string()))
        })
        .collect();
    if !cropped.is_empty() {
        let _ = writeln!(
            s,
            "Caustic windows scored against a reference of the window alone, rendered with more samples \
             (suite.toml's `caustic_reference`), whose noise is the caustic noise above: {}.\n",
            cropped.join(", ")
        );
    }
    let _ = writeln!(s, "## The scenes\n\nEach picture: photonmap's default render (reduced to 200 x 200) | the reference | the signed difference (red: photonmap brighter, blue: darker).\n");
    for r in rows {
        let comment = suite
            .iter()
            .find(|x| x.name == r.name)
            .and_then(|x| std::fs::read_to_string(&x.scene).ok())
            .map(|t| {
                t.lines()
                    .take_while(|l| l.starts_with('#'))
                    .map(|l| l.trim_start_matches('#').trim())
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .unwrap_or_default();
        let _ = writeln!(s, "### {}\n\n{comment}\n\n![{}](suite/{}.png)\n", r.name, r.name, r.name);
    }
    s
}

fn csv(rows: &[Row]) -> String {
    let mut s = String::from("scene,run,seconds,count,bias,caustic_bias,rmse,caustic_rmse,speckles\n");
    for r in rows {
        let runs = [
            ("default", Some(&r.classic)),
            ("progressive", r.progressive.as_ref()),
            ("mitsuba_default", r.mitsuba_classic.as_ref()),
            ("mitsuba_progressive", r.mitsuba_progressive.as_ref()),
        ];
        for (run, x) in runs {
            if let Some(x) = x {
                let _ = writeln!(
                    s,
                    "{},{run},{:.2},{},{:.5},{:.5},{:.6},{:.6},{}",
                    r.name,
                    x.seconds,
                    x.count,
                    x.c.whole.bias(),
                    x.c.windows[0].1.bias(),
                    x.rmse,
                    x.caustic_rmse,
                    x.c.speckles
                );
            }
        }
    }
    s
}

/// What an RMSE of zero means, and for each such entry the least ratio
/// the reference allows: Mitsuba's error over the reference's noise.
fn below_noise(rows: &[Row], seconds: f64) -> String {
    let mut bounds = Vec::new();
    let timed = format!("{seconds:.0} s");
    for r in rows {
        let runs = [
            ("default", Some(&r.classic), r.mitsuba_classic.as_ref()),
            (timed.as_str(), r.progressive.as_ref(), r.mitsuba_progressive.as_ref()),
        ];
        for (run, p, m) in runs {
            let (Some(p), Some(m)) = (p, m) else { continue };
            let bound = |ours: f64, theirs: f64, noise: Option<f64>| match noise {
                Some(n) if ours == 0.0 && n > 0.0 => Some(format!("{:.1}x", theirs / n)),
                _ => None,
            };
            let whole = bound(p.rmse, m.rmse, r.noise.0);
            let caustic = bound(p.caustic_rmse, m.caustic_rmse, r.noise.1);
            if whole.is_some() || caustic.is_some() {
                let at_least = |b: Option<String>, what: &str| b.map(|b| format!("{b} {what}"));
                let parts: Vec<String> =
                    [at_least(whole, "whole"), at_least(caustic, "caustic window")].into_iter().flatten().collect();
                bounds.push(format!("{} {run}: at least {}", r.name, parts.join(", ")));
            }
        }
    }
    let mut text = String::from(
        "An RMSE of 0.00000 and a ratio \"—\": photonmap's error cannot be measured against the reference, what \
         it exceeds the reference's own noise by being within three standard errors of that noise's estimate \
         (`photonmap::suite::less_noise`); Mitsuba's error over the reference's noise bounds the ratio from below",
    );
    if bounds.is_empty() {
        text.push_str(".\n");
    } else {
        text.push_str(&format!(" ({}).\n", bounds.join("; ")));
    }
    text
}
