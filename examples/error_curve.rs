//! Run time against error on the default scene: classic photon mapping at
//! several photon counts, progressive photon mapping and path tracing at
//! several time budgets, each scored against the reference.
//!
//! `cargo run --release --example error_curve [-- --quick]` writes
//! notes/error_curve.csv and notes/error_curve.svg (log-log, one line per
//! integrator and metric). Run it on an otherwise idle machine: the wall
//! times are the result. `--quick` uses short budgets (a smoke run);
//! `--replot` redraws the SVG from the CSV without rendering.

use photonmap::metrics::{compare, Metrics};
use photonmap::output::read_exr;
use photonmap::progress::Mode;
use photonmap::render::{render, render_progressive, Budget};
use photonmap::scene::{Eye, Scene};
use photonmap::settings::{Method, Settings};
use plotters::prelude::*;
use std::io::Write;
use std::time::Instant;

struct Row {
    integrator: &'static str,
    setting: String,
    seconds: f64,
    passes: u32,
    m: Metrics,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let quick = std::env::args().any(|a| a == "--quick");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    if std::env::args().any(|a| a == "--replot") {
        let rows = read_csv(&root.join("notes/error_curve.csv"))?;
        plot(&root.join("notes/error_curve.svg"), &rows)?;
        return Ok(());
    }
    let reference = read_exr(&root.join("tests/data/default_e1_200.exr"))?;
    let scene = Scene::tncg15(Eye::One);
    let budgets: &[f64] = if quick { &[2.0, 4.0] } else { &[3.75, 5.0, 15.0, 20.0, 60.0, 240.0] };
    let counts: &[u64] = if quick { &[100_000] } else { &[100_000, 1_000_000, 10_000_000] };
    let mut rows = Vec::new();
    let mut record = |row: Row| {
        eprintln!(
            "{:>8} {:>14}  {:>7.1} s  {:>5} passes  rmse {:.5}  relmse {:.6}  caustic {:.5}  mean {:.5}",
            row.integrator,
            row.setting,
            row.seconds,
            row.passes,
            row.m.rmse,
            row.m.relmse,
            row.m.caustic_rmse,
            row.m.mean_x
        );
        rows.push(row);
    };

    for &photons in counts {
        let settings = Settings { photons, caustic_photons: photons, ..Settings::default() };
        let t = Instant::now();
        let (film, _) = render(&scene, &settings, Mode::Quiet);
        let seconds = t.elapsed().as_secs_f64();
        let m = compare(&film, &reference).ok_or("size")?;
        record(Row { integrator: "classic", setting: format!("{photons:.0e} photons"), seconds, passes: 1, m });
    }
    // Progressive photon mapping: 2.5e5 + 2.5e5 photons and 1 spp per pass.
    let ppm = Settings { photons: 250_000, caustic_photons: 250_000, spp: 1, ..Settings::default() };
    let path = Settings { method: Method::Path, spp: 1, ..Settings::default() };
    for (name, settings) in [("ppm", ppm), ("path", path)] {
        for &budget in budgets {
            let t = Instant::now();
            let (film, stats) = render_progressive(&scene, &settings, Budget::seconds(budget), |_| {});
            let seconds = t.elapsed().as_secs_f64();
            let m = compare(&film, &reference).ok_or("size")?;
            record(Row { integrator: name, setting: format!("{budget} s budget"), seconds, passes: stats.passes, m });
        }
    }

    let csv_path = root.join(if quick { "target/error_curve_quick.csv" } else { "notes/error_curve.csv" });
    let mut csv = std::fs::File::create(&csv_path)?;
    writeln!(
        csv,
        "integrator,setting,seconds,passes,rmse,relmse,caustic_rmse,mean_x,mean_r,caustic_mean_x,caustic_mean_r"
    )?;
    for r in &rows {
        writeln!(
            csv,
            "{},{},{:.3},{},{:.6},{:.7},{:.6},{:.6},{:.6},{:.6},{:.6}",
            r.integrator,
            r.setting,
            r.seconds,
            r.passes,
            r.m.rmse,
            r.m.relmse,
            r.m.caustic_rmse,
            r.m.mean_x,
            r.m.mean_r,
            r.m.caustic_mean_x,
            r.m.caustic_mean_r
        )?;
    }
    let svg_path = root.join(if quick { "target/error_curve_quick.svg" } else { "notes/error_curve.svg" });
    plot(&svg_path, &rows)?;
    eprintln!("wrote {} and {}", csv_path.display(), svg_path.display());
    Ok(())
}

fn read_csv(path: &std::path::Path) -> Result<Vec<Row>, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(path)?;
    let mut rows = Vec::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| -> Result<f64, Box<dyn std::error::Error>> { Ok(f.get(i).ok_or("short row")?.parse()?) };
        let integrator = match f[0] {
            "classic" => "classic",
            "ppm" => "ppm",
            "path" => "path",
            other => return Err(format!("unknown integrator {other}").into()),
        };
        rows.push(Row {
            integrator,
            setting: f[1].to_string(),
            seconds: num(2)?,
            passes: num(3)? as u32,
            m: Metrics {
                rmse: num(4)?,
                relmse: num(5)?,
                caustic_rmse: num(6)?,
                mean_x: num(7)?,
                mean_r: num(8)?,
                caustic_mean_x: num(9)?,
                caustic_mean_r: num(10)?,
                nan_count: 0,
            },
        });
    }
    Ok(rows)
}

/// The refs README's Mitsuba path-tracer figures (seconds, rmse, caustic rmse).
const MITSUBA: [(f64, f64, f64); 5] =
    [(1.2, 0.053, 0.208), (1.3, 0.026, 0.117), (5.2, 0.0134, 0.056), (22.9, 0.0066, 0.026), (87.0, 0.0036, 0.015)];

fn plot(path: &std::path::Path, rows: &[Row]) -> Result<(), Box<dyn std::error::Error>> {
    let area = SVGBackend::new(path, (900, 640)).into_drawing_area();
    area.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&area)
        .caption("TNCG15 default scene: error against wall time (2-core machine)", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((1.0f64..400.0).log_scale(), (0.0005f64..0.3).log_scale())?;
    chart.configure_mesh().x_desc("wall time (s)").y_desc("RMSE vs reference (200x200 metric)").draw()?;
    let series: [(&str, &str, RGBColor); 3] =
        [("classic", "classic PM", BLUE), ("ppm", "progressive PM", RED), ("path", "path tracer", GREEN)];
    for (key, label, color) in series {
        let pts: Vec<&Row> = rows.iter().filter(|r| r.integrator == key).collect();
        for (metric, dashed) in [("rmse", false), ("caustic rmse", true)] {
            let line: Vec<(f64, f64)> =
                pts.iter().map(|r| (r.seconds, if dashed { r.m.caustic_rmse } else { r.m.rmse })).collect();
            let style = if dashed { color.mix(0.6).stroke_width(1) } else { color.stroke_width(2) };
            chart
                .draw_series(LineSeries::new(line.clone(), style))?
                .label(format!("{label}, {metric}"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            chart.draw_series(line.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
        }
    }
    for (dashed, idx) in [(false, 1usize), (true, 2usize)] {
        let line: Vec<(f64, f64)> = MITSUBA.iter().map(|m| (m.0, if idx == 1 { m.1 } else { m.2 })).collect();
        let style = if dashed { BLACK.mix(0.5).stroke_width(1) } else { BLACK.stroke_width(2) };
        chart
            .draw_series(LineSeries::new(line, style))?
            .label(format!("Mitsuba 3 path (refs README), {}", if dashed { "caustic rmse" } else { "rmse" }))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    area.present()?;
    Ok(())
}
