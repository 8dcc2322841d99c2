//! The command line: options, dispatch, progress and statistics.

use clap::Parser;
use std::path::PathBuf;

mod check;
pub mod converge;
mod render;

/// pbrs: render a pbrt-v3 scene.
#[derive(Parser, Debug, Clone)]
#[command(
    name = "pbrs",
    version,
    about = "A physically based renderer for pbrt-v3 scenes",
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Args {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// The scene file (pbrt-v3 format).
    #[arg(required = true)]
    pub scene: Option<PathBuf>,
    /// Parse and build the scene, print warnings and a summary, do not render.
    #[arg(long)]
    pub check: bool,
    /// Output image (.exr, .png or .pfm); overrides the Film's filename.
    #[arg(long, short = 'o')]
    pub outfile: Option<PathBuf>,
    /// Samples per pixel; overrides the sampler's pixelsamples.
    #[arg(long)]
    pub spp: Option<u32>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seed for the sampler's scrambling and random dimensions.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Crop window in NDC: x0 x1 y0 y1; overrides the Film's cropwindow.
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"], allow_negative_numbers = true)]
    pub cropwindow: Option<Vec<f32>>,
    /// No progress bar, no summary.
    #[arg(long, short = 'q')]
    pub quiet: bool,
    /// Print detailed statistics: what was built and skipped, rays, timings.
    #[arg(long)]
    pub stats: bool,
}

impl Args {
    /// The scene file (clap guarantees it unless a subcommand is given).
    pub fn scene_path(&self) -> &std::path::Path {
        self.scene.as_deref().unwrap_or(std::path::Path::new(""))
    }
}

#[derive(clap::Subcommand, Debug, Clone)]
pub enum Command {
    /// Error against run time: progressive renders compared with a reference.
    Converge(converge::ConvergeArgs),
}

/// Runs the command line; returns the process exit status.
pub fn main() -> i32 {
    let args = Args::parse();
    if let Some(Command::Converge(c)) = &args.command {
        return converge::run(c);
    }
    if args.check {
        check::run(&args)
    } else {
        render::run(&args)
    }
}
