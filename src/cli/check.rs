//! `pbrs --check`: parse and build, print warnings and a summary.

use super::render::scenes_label;
use super::Args;
use crate::loader::{load_scene_files_each, print_diagnostics, strictly};

/// Parses and builds the scene files without rendering. Prints the warnings,
/// then the summary and what was left out (exit 0), or the errors (exit 1).
pub fn run(args: &Args) -> i32 {
    let label = scenes_label(args);
    match load_scene_files_each(&args.scenes).and_then(|s| {
        if args.strict {
            strictly(s)
        } else {
            Ok(s)
        }
    }) {
        Ok(scenes) => {
            let n = scenes.len();
            if n == 0 {
                println!("{label}: empty: nothing to render");
            }
            for (i, loaded) in scenes.iter().enumerate() {
                if args.warnings() {
                    print_diagnostics(&loaded.warnings);
                }
                if n > 1 {
                    println!("{label} (world block {} of {n})", i + 1);
                } else {
                    println!("{label}");
                }
                println!("{}", loaded.summary);
                if !loaded.scene.skipped.is_empty() {
                    println!("left out:");
                    for s in &loaded.scene.skipped {
                        println!("  - {s}");
                    }
                }
            }
            0
        }
        Err(failure) => {
            if args.warnings() {
                print_diagnostics(&failure.warnings);
            }
            print_diagnostics(&failure.errors);
            let n = failure.errors.len();
            eprintln!(
                "{label}: {n} error{}; the scene was not loaded",
                if n == 1 { "" } else { "s" }
            );
            1
        }
    }
}
