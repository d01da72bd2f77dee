//! How good is the error estimate? On every suite scene, a progressive
//! render (default progressive settings, at the reference's 200 x 200)
//! compares its predicted RMSE with the RMSE measured against the scene's
//! independent reference, less the reference's own noise in quadrature,
//! after 4, 16, 64 and 200 passes, for the whole image and the caustic
//! window.
//!
//! `cargo run --release --example calibration [-- --only NAME ...] [--passes N]`
//! updates notes/calibration.csv after each scene (the rows of the scenes
//! rendered are replaced, the others kept, so a long run can be done a few
//! scenes at a time) and redraws notes/calibration.svg (predicted against
//! measured, log-log, the band of a factor 1.5 drawn); `--replot` only
//! redraws the plot from the CSV.

use photonmap::film::accumulation::Accumulation;
use photonmap::render::{render_passes, Budget};
use photonmap::scene::Scene;
use photonmap::settings::{
    default_global_photons, progressive_caustics, Settings, PROGRESSIVE_PHOTONS, PROGRESSIVE_SPP,
};
use plotters::prelude::*;
use std::io::Write;
use std::ops::ControlFlow;
use std::path::Path;

struct Row {
    scene: String,
    region: &'static str,
    passes: u32,
    seconds: f64,
    predicted: f64,
    predicted_noise: f64,
    predicted_bias: f64,
    measured: f64,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let only: Vec<&String> = args.windows(2).filter(|w| w[0] == "--only").map(|w| &w[1]).collect();
    let last: u32 = args.windows(2).find(|w| w[0] == "--passes").map_or(Ok(200), |w| w[1].parse())?;
    let checkpoints: Vec<u32> = [4, 16, 64, 200].into_iter().filter(|&p| p <= last).collect();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    photonmap::scene::procedural::write_suite_meshes(&root.join("scenes/suite/meshes"), true)?;
    let suite = photonmap::suite::load(&root.join("scenes/suite"))?;
    let notes = root.join("notes");
    let mut rows = read_csv(&notes.join("calibration.csv"))?;
    if args.iter().any(|a| a == "--replot") {
        plot(&notes.join("calibration.svg"), &rows)?;
        eprintln!("wrote notes/calibration.svg from {} rows", rows.len());
        return Ok(());
    }
    for s in suite.iter().filter(|s| only.is_empty() || only.contains(&&s.name)) {
        let mut new_rows = Vec::new();
        let scoring = s.scoring()?;
        let reference = &scoring.reference;
        let file = photonmap::scene::file::load(&s.scene)?;
        let scene = Scene::from_parts(file.parts);
        let (caustic_photons, k_caustic) = progressive_caustics(scene.media().is_some());
        let settings = Settings {
            photons: default_global_photons(PROGRESSIVE_PHOTONS, scene.media().is_some()),
            caustic_photons,
            k_caustic,
            spp: PROGRESSIVE_SPP,
            width: reference.width,
            height: reference.height,
            ..Settings::default()
        };
        let budget = Budget { end: Some(last), windows: vec![s.caustic.clone()], ..Budget::default() };
        let acc = Accumulation::new(settings.width, settings.height);
        render_passes(&scene, &settings, acc, 0, &budget, |r| {
            if !checkpoints.contains(&r.passes) {
                return ControlFlow::Continue(());
            }
            let score = scoring.score(r.film).expect("a render of the reference's size");
            let measured = [score.rmse, score.caustic_rmse];
            for (i, region) in ["image", "caustic"].into_iter().enumerate() {
                let p = &r.predictions[i].1;
                let row = Row {
                    scene: s.name.clone(),
                    region,
                    passes: r.passes,
                    seconds: r.elapsed.as_secs_f64(),
                    predicted: p.rmse,
                    predicted_noise: p.noise_rmse,
                    predicted_bias: p.bias_rmse,
                    measured: measured[i],
                };
                eprintln!(
                    "{:<16} {:<8} {:>4} passes {:>7.1} s  predicted {:.5} (noise {:.5}, bias {:.5})  measured {:.5}  ratio {:.2}",
                    row.scene,
                    row.region,
                    row.passes,
                    row.seconds,
                    row.predicted,
                    row.predicted_noise,
                    row.predicted_bias,
                    row.measured,
                    row.predicted / row.measured
                );
                new_rows.push(row);
            }
            ControlFlow::Continue(())
        });
        // Re-read: another run may have updated other scenes meanwhile.
        rows = read_csv(&notes.join("calibration.csv"))?;
        rows.retain(|r| r.scene != s.name);
        rows.extend(new_rows);
        rows.sort_by(|a, b| (&a.scene, a.passes, a.region != "image").cmp(&(&b.scene, b.passes, b.region != "image")));
        write_csv(&notes.join("calibration.csv"), &rows)?;
        plot(&notes.join("calibration.svg"), &rows)?;
        eprintln!("updated notes/calibration.csv and notes/calibration.svg ({} rows)", rows.len());
    }
    Ok(())
}

fn read_csv(path: &Path) -> Result<Vec<Row>, Box<dyn std::error::Error>> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e.into()),
    };
    let mut rows = Vec::new();
    for line in text.lines().skip(1).filter(|l| !l.trim().is_empty()) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() < 8 {
            return Err(format!("{}: short line {line:?}", path.display()).into());
        }
        rows.push(Row {
            scene: f[0].to_string(),
            region: if f[1] == "image" { "image" } else { "caustic" },
            passes: f[2].parse()?,
            seconds: f[3].parse()?,
            predicted: f[4].parse()?,
            predicted_noise: f[5].parse()?,
            predicted_bias: f[6].parse()?,
            measured: f[7].parse()?,
        });
    }
    Ok(rows)
}

fn write_csv(path: &Path, rows: &[Row]) -> Result<(), Box<dyn std::error::Error>> {
    let tmp = path.with_extension("csv.tmp");
    let mut csv = std::fs::File::create(&tmp)?;
    writeln!(csv, "scene,region,passes,seconds,predicted_rmse,predicted_noise,predicted_bias,measured_rmse,ratio")?;
    for r in rows {
        writeln!(
            csv,
            "{},{},{},{:.2},{:.6},{:.6},{:.6},{:.6},{:.3}",
            r.scene,
            r.region,
            r.passes,
            r.seconds,
            r.predicted,
            r.predicted_noise,
            r.predicted_bias,
            r.measured,
            r.predicted / r.measured
        )?;
    }
    drop(csv);
    std::fs::rename(tmp, path)?;
    Ok(())
}

fn plot(path: &Path, rows: &[Row]) -> Result<(), Box<dyn std::error::Error>> {
    let values = rows.iter().flat_map(|r| [r.predicted, r.measured]).filter(|v| *v > 0.0);
    let (lo, hi) = values.fold((f64::MAX, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let (lo, hi) = (lo / 1.5, hi * 1.5);
    let svg = SVGBackend::new(path, (720, 640)).into_drawing_area();
    svg.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&svg)
        .caption("Predicted against measured RMSE (suite, 4-200 passes)", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((lo..hi).log_scale(), (lo..hi).log_scale())?;
    chart.configure_mesh().x_desc("measured RMSE (reference noise removed)").y_desc("predicted RMSE").draw()?;
    for (factor, style) in [(1.0, BLACK), (1.5, RGBColor(150, 150, 150)), (1.0 / 1.5, RGBColor(150, 150, 150))] {
        chart.draw_series(LineSeries::new([(lo, lo * factor), (hi, hi * factor)], style))?;
    }
    for (region, colour) in [("image", BLUE), ("caustic", RED)] {
        chart
            .draw_series(
                rows.iter()
                    .filter(|r| r.region == region && r.measured > 0.0)
                    .map(|r| Circle::new((r.measured, r.predicted), 3, colour.filled())),
            )?
            .label(if region == "image" { "whole image" } else { "caustic window" })
            .legend(move |(x, y)| Circle::new((x, y), 3, colour.filled()));
    }
    chart.configure_series_labels().background_style(WHITE).border_style(BLACK).draw()?;
    svg.present()?;
    Ok(())
}
