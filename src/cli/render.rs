//! Rendering from the command line: load, apply overrides, render with a
//! progress bar, write the image atomically, print a summary.

use super::Args;
use crate::loader::{load_scene, print_diagnostics};
use crate::render::driver::{peak_memory_bytes, render, RenderOptions};
use crate::render::film::io::{check_output_path, write_image};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// Largest sample count accepted from the command line (as the scene builder).
const MAX_SPP: u32 = 1 << 24;

fn fail(msg: impl std::fmt::Display) -> i32 {
    eprintln!("error: {msg}");
    1
}

pub fn run(args: &Args) -> i32 {
    let loaded = match load_scene(args.scene_path()) {
        Ok(l) => l,
        Err(f) => {
            print_diagnostics(&f.warnings);
            print_diagnostics(&f.errors);
            eprintln!(
                "{}: the scene was not loaded; no image was written",
                args.scene_path().display()
            );
            return 1;
        }
    };
    print_diagnostics(&loaded.warnings);
    let mut desc = loaded.scene;

    // Command-line overrides, validated before any work is done.
    if let Some(spp) = args.spp {
        if spp == 0 || spp > MAX_SPP {
            return fail(format!("--spp must be between 1 and {MAX_SPP}, not {spp}"));
        }
        desc.sampler.pixel_samples = spp;
    }
    if let Some(c) = &args.cropwindow {
        let ok = c.len() == 4
            && c.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v))
            && c[0] < c[1]
            && c[2] < c[3];
        if !ok {
            return fail("--cropwindow takes X0 X1 Y0 Y1 in [0, 1] with X0 < X1 and Y0 < Y1");
        }
        desc.film.cropwindow = [c[0], c[1], c[2], c[3]];
    }
    if let Some(out) = &args.outfile {
        desc.film.filename = out.clone();
    }
    if args.threads == Some(0) {
        return fail("--threads must be at least 1");
    }
    let out = desc.film.filename.clone();
    if let Err(e) = check_output_path(&out) {
        return fail(format!("cannot write {}: {e}", out.display()));
    }

    let show_progress = !args.quiet && std::io::stderr().is_terminal();
    let bar = if show_progress {
        let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("{spinner} rendering [{bar:40}] {percent:>3}% {elapsed_precise} elapsed, {eta} left")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let opts = RenderOptions {
        threads: args.threads,
        seed: args.seed,
        ..Default::default()
    };
    let progress = |done: usize, total: usize| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    };
    let (image, stats) = match render(&desc, &opts, &progress) {
        Ok(r) => r,
        Err(e) => return fail(e),
    };
    bar.finish_and_clear();
    if let Err(e) = write_image(&out, &image) {
        return fail(format!("cannot write {}: {e}", out.display()));
    }
    if !args.quiet {
        let mem = peak_memory_bytes().map_or("unknown".to_string(), |b| {
            format!("{:.1} MiB", b as f64 / (1024.0 * 1024.0))
        });
        eprintln!(
            "{}: {}x{} px, {} spp, {} threads; build {:.2} s, render {:.2} s; {:.1} M rays ({:.1} M closest-hit + {:.1} M shadow), {:.2} Mrays/s; {} samples dropped (NaN {}, Inf {}, negative {}); peak memory {}",
            out.display(),
            image.width,
            image.height,
            desc.sampler.pixel_samples,
            stats.threads,
            stats.build_time.as_secs_f64(),
            stats.render_time.as_secs_f64(),
            stats.rays.total() as f64 / 1e6,
            stats.rays.closest as f64 / 1e6,
            stats.rays.shadow as f64 / 1e6,
            stats.mrays_per_sec(),
            stats.dropped_samples(),
            stats.nan_samples,
            stats.inf_samples,
            stats.negative_samples,
            mem
        );
    }
    if args.stats {
        eprintln!("statistics:");
        for n in desc
            .skipped
            .iter()
            .map(|s| format!("left out: {s}"))
            .chain(stats.notes.iter().cloned())
        {
            eprintln!("  {n}");
        }
        eprintln!("  samples: {}", stats.samples);
        eprintln!(
            "  rays: {} closest-hit, {} shadow",
            stats.rays.closest, stats.rays.shadow
        );
    }
    0
}
