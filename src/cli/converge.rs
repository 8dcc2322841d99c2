//! `pbrs converge`: error against run time. Renders each configuration
//! progressively (doubling the sample count within one run), measures the
//! error against a converged reference at every step, and writes a CSV, a
//! log-log plot (SVG) with fitted slopes, and a table of efficiencies
//! 1/(MSE × time), the figure of merit of the seed text.

use crate::image::compare::compare;
use crate::image::io::{read_image, write_atomic};
use crate::loader::{load_scene, print_diagnostics};
use crate::render::driver::{RenderOptions, Renderer};
use crate::scene::IntegratorSettings;
use clap::Args as ClapArgs;
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(ClapArgs, Debug, Clone)]
pub struct ConvergeArgs {
    /// The scene to study.
    pub scene: PathBuf,
    /// Converged reference image (.pfm or .exr); renders use its resolution.
    #[arg(long)]
    pub reference: PathBuf,
    /// Largest sample count (powers of two from 1 up to this).
    #[arg(long, default_value_t = 256)]
    pub spp_max: u32,
    /// Other scene files to compare: `SCENE` (same reference) or
    /// `SCENE=REFERENCE` (its own reference, e.g. for another integrator).
    #[arg(long, num_args = 1..)]
    pub compare: Vec<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Output directory for converge.csv and converge.svg.
    #[arg(long, default_value = "converge")]
    pub out: PathBuf,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

/// One measurement.
#[derive(Clone, Debug)]
pub struct Step {
    pub spp: u32,
    pub seconds: f64,
    pub rmse: f64,
    pub relative_mse: f64,
    pub block_error: f64,
}

/// Least-squares slope of log(y) against log(x).
pub fn log_log_slope(points: &[(f64, f64)]) -> f64 {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = pts.len() as f64;
    if pts.len() < 2 {
        return f64::NAN;
    }
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    sxy / sxx
}

/// What a step's count is: samples per pixel, sppm's iterations or mlt's
/// mutations per pixel.
fn effort_unit(i: &IntegratorSettings) -> &'static str {
    match i {
        IntegratorSettings::Sppm(_) => "iterations",
        IntegratorSettings::Mlt(_) => "mutations/px",
        _ => "spp",
    }
}

fn label(p: &std::path::Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.display().to_string())
}

pub fn run(args: &ConvergeArgs) -> i32 {
    let read =
        |p: &std::path::Path| read_image(p).map_err(|e| format!("cannot read the reference: {e}"));
    let mut configs = vec![(args.scene.clone(), args.reference.clone())];
    for c in &args.compare {
        let s = c.to_string_lossy();
        match s.split_once('=') {
            Some((scene, r)) => configs.push((PathBuf::from(scene), PathBuf::from(r))),
            None => configs.push((c.clone(), args.reference.clone())),
        }
    }
    if args.spp_max == 0 || args.spp_max > 1 << 20 {
        eprintln!("error: --spp-max must be between 1 and 2^20");
        return 1;
    }
    let mut results: Vec<(String, Vec<Step>)> = Vec::new();
    for (scene, reference) in &configs {
        let reference = match read(reference) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("error: {e}");
                return 1;
            }
        };
        let loaded = match load_scene(scene) {
            Ok(l) => l,
            Err(f) => {
                print_diagnostics(&f.errors);
                return 1;
            }
        };
        let mut desc = loaded.scene;
        desc.film.xresolution = reference.width;
        desc.film.yresolution = reference.height;
        desc.film.cropwindow = [0.0, 1.0, 0.0, 1.0];
        desc.sampler.pixel_samples = args.spp_max;
        // sppm and mlt are not progressive in samples: each step is a
        // render of its own with that many iterations (sppm) or mutations
        // per pixel (mlt), timed alone.
        let own_effort = matches!(
            desc.integrator,
            IntegratorSettings::Sppm(_) | IntegratorSettings::Mlt(_)
        );
        let options = RenderOptions {
            threads: args.threads,
            seed: args.seed,
            ..Default::default()
        };
        let mut progressive = None;
        let mut steps = Vec::new();
        let (mut done, mut spp) = (0u32, 1u32);
        while spp <= args.spp_max {
            let made = if own_effort {
                let mut d = desc.clone();
                match &mut d.integrator {
                    IntegratorSettings::Sppm(s) => s.iterations = spp,
                    IntegratorSettings::Mlt(m) => m.mutations_per_pixel = spp,
                    _ => {}
                }
                Renderer::new(&d, &options).map(|mut r| {
                    r.render_samples(0..spp, &|_, _| {});
                    r
                })
            } else {
                let r = match progressive.take() {
                    Some(r) => Ok(r),
                    None => Renderer::new(&desc, &options),
                };
                r.map(|mut r| {
                    r.render_samples(done..spp, &|_, _| {});
                    r
                })
            };
            let r = match made {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("error: {e}");
                    return 1;
                }
            };
            done = spp;
            let st = r.stats();
            let c = compare(&r.image(), &reference);
            let step = Step {
                spp,
                seconds: (st.build_time + st.render_time).as_secs_f64(),
                rmse: c.rmse,
                relative_mse: c.relative_mse,
                block_error: c.block_error,
            };
            eprintln!(
                "{}: {:>6} {} {:>8.3} s  RMSE {:.5}  rel. MSE {:.3e}  block {:.3e}",
                label(scene),
                step.spp,
                effort_unit(&desc.integrator),
                step.seconds,
                step.rmse,
                step.relative_mse,
                step.block_error
            );
            steps.push(step);
            if !own_effort {
                progressive = Some(r);
            }
            spp = match spp.checked_mul(2) {
                Some(s) => s,
                None => break,
            };
        }
        results.push((label(scene), steps));
    }

    if let Err(e) = std::fs::create_dir_all(&args.out) {
        eprintln!("error: cannot create {}: {e}", args.out.display());
        return 1;
    }
    let mut csv = String::from("config,spp,seconds,rmse,relative_mse,block_error\n");
    for (name, steps) in &results {
        for s in steps {
            let _ = writeln!(
                csv,
                "{name},{},{:.6},{:.8e},{:.8e},{:.8e}",
                s.spp, s.seconds, s.rmse, s.relative_mse, s.block_error
            );
        }
    }
    let csv_path = args.out.join("converge.csv");
    let svg_path = args.out.join("converge.svg");
    if let Err(e) = write_atomic(&csv_path, csv.as_bytes()) {
        eprintln!("error: {e}");
        return 1;
    }
    // Slopes over the steps past the first two (start-up dominates those).
    let slopes: Vec<f64> = results
        .iter()
        .map(|(_, s)| {
            log_log_slope(
                &s.iter()
                    .skip(2)
                    .map(|x| (x.seconds, x.relative_mse))
                    .collect::<Vec<_>>(),
            )
        })
        .collect();
    if let Err(e) = plot(&svg_path, &results, &slopes) {
        eprintln!("error: cannot draw {}: {e}", svg_path.display());
        return 1;
    }
    println!("| configuration | spp | time s | RMSE | rel. MSE | slope (rel. MSE vs time) | efficiency 1/(MSE·s) |");
    println!("|---|---|---|---|---|---|---|");
    for ((name, steps), slope) in results.iter().zip(&slopes) {
        if let Some(last) = steps.last() {
            println!(
                "| {name} | {} | {:.2} | {:.5} | {:.3e} | {:.2} | {:.4e} |",
                last.spp,
                last.seconds,
                last.rmse,
                last.relative_mse,
                slope,
                1.0 / (last.rmse * last.rmse * last.seconds)
            );
        }
    }
    println!("wrote {} and {}", csv_path.display(), svg_path.display());
    0
}

fn plot(
    path: &std::path::Path,
    results: &[(String, Vec<Step>)],
    slopes: &[f64],
) -> Result<(), String> {
    use plotters::prelude::*;
    let pts = results.iter().flat_map(|(_, s)| s.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for s in pts {
        if s.seconds > 0.0 && s.relative_mse > 0.0 {
            x0 = x0.min(s.seconds);
            x1 = x1.max(s.seconds);
            y0 = y0.min(s.relative_mse);
            y1 = y1.max(s.relative_mse);
        }
    }
    if !(x0 < x1 && y0 < y1) {
        return Err("not enough data to plot".into());
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (800, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
            .caption("relative MSE against render time", ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(72)
            .build_cartesian_2d(
                (x0 * 0.8..x1 * 1.25).log_scale(),
                (y0 * 0.8..y1 * 1.25).log_scale(),
            )
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc("relative MSE")
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, ((name, steps), slope)) in results.iter().zip(slopes).enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            let data: Vec<(f64, f64)> = steps.iter().map(|s| (s.seconds, s.relative_mse)).collect();
            chart
                .draw_series(LineSeries::new(data.clone(), colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(format!("{name} (slope {slope:.2})"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
            chart
                .draw_series(data.into_iter().map(|p| Circle::new(p, 3, colour.filled())))
                .map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    write_atomic(path, svg.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::log_log_slope;

    #[test]
    fn slope_of_a_power_law() {
        let pts: Vec<(f64, f64)> = (1..10).map(|i| (i as f64, 3.0 / i as f64)).collect();
        assert!((log_log_slope(&pts) + 1.0).abs() < 1e-12);
    }
}
