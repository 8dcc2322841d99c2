//! `pbrs --check`: parse and build, print warnings and a summary.

use super::Args;
use crate::loader::{load_scene, print_diagnostics};

/// Parses and builds `args.scene` without rendering. Prints the warnings, then the
/// summary and what was left out (exit 0), or the errors (exit 1).
pub fn run(args: &Args) -> i32 {
    match load_scene(args.scene_path()) {
        Ok(loaded) => {
            print_diagnostics(&loaded.warnings);
            println!("{}", args.scene_path().display());
            println!("{}", loaded.summary);
            if !loaded.scene.skipped.is_empty() {
                println!("left out:");
                for s in &loaded.scene.skipped {
                    println!("  - {s}");
                }
            }
            0
        }
        Err(failure) => {
            print_diagnostics(&failure.warnings);
            print_diagnostics(&failure.errors);
            let n = failure.errors.len();
            eprintln!(
                "{}: {n} error{}; the scene was not loaded",
                args.scene_path().display(),
                if n == 1 { "" } else { "s" }
            );
            1
        }
    }
}
