//! Rendering from the command line.

use super::Args;

pub fn run(_args: &Args) -> i32 {
    eprintln!("rendering is not implemented yet");
    1
}
