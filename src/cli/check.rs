//! `pbrs --check`: parse and build, print warnings and a summary.

use super::Args;

pub fn run(_args: &Args) -> i32 {
    eprintln!("--check is not implemented yet");
    1
}
