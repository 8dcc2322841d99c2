//! The command line: options, dispatch, progress and statistics.
//!
//! pbrs takes pbrt-v3's flags as pbrt-v3 spells them (one or two dashes,
//! `--flag value` or `--flag=value`) and pbrt-v4's rendering flags; argv is
//! normalised for clap by [`args::normalize`] first. Exit status: 0 success,
//! 1 scene or render error, 2 usage error.

use clap::{CommandFactory, Parser};
use std::ffi::OsString;
use std::path::PathBuf;

mod args;
mod cat;
mod check;
pub mod converge;
pub mod display;
pub mod golden;
pub mod img;
pub mod merge;
mod render;

/// Exit status of a usage error (clap's own).
pub const USAGE_ERROR: i32 = 2;

/// pbrs: render a pbrt-v3 scene.
#[derive(Parser, Debug, Clone)]
#[command(
    name = "pbrs",
    version,
    about = "A physically based renderer for pbrt-v3 scenes",
    after_help = "pbrt's command lines work unchanged: every flag takes one or two dashes and \
                  `--flag value` or `--flag=value`; --cropwindow and --pixelbounds also take \
                  pbrt-v4's single `x0,x1,y0,y1`. Where pbrt-v3 and pbrt-v4 differ, pbrs \
                  follows pbrt-v3 (noted at the flag).\n\
                  Exit status: 0 success, 1 scene or render error, 2 usage error.",
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    // pbrt takes a flag given twice; the last one counts.
    args_override_self = true
)]
pub struct Args {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Scene files (pbrt-v3 format), parsed in order as one scene; each world
    /// block renders at its WorldEnd, from a fresh state (as pbrt-v3, so
    /// several complete scenes render in turn). `-` reads standard input, as does giving none when standard input is
    /// not a terminal. Each file's names are relative to its own directory
    /// (standard input's: the current directory).
    #[arg(value_name = "SCENE")]
    pub scenes: Vec<PathBuf>,
    /// Parse and build the scene, print warnings and a summary, do not render.
    #[arg(long)]
    pub check: bool,
    /// Make every warning an error (a substitution, an ignored feature, a
    /// file that could not be read): exit 1 and write nothing, where
    /// pbrt-v3 (and pbrs by default) would render on.
    #[arg(long)]
    pub strict: bool,
    /// Print the scene as pbrs read it (Includes spliced, one directive per
    /// line, parameters normalised, file names resolved against the current
    /// directory) to standard output; do not render (pbrt-v3's --cat;
    /// pbrt-v4 calls it --format).
    #[arg(long, visible_alias = "format", help_heading = "Scene tools")]
    pub cat: bool,
    /// As --cat, and write each trianglemesh with 500 indices or more to
    /// mesh_NNNNN.ply in the current directory (prefix: $PLY_PREFIX), printed
    /// as a plymesh (pbrt-v3's --toply).
    #[arg(long, help_heading = "Scene tools")]
    pub toply: bool,
    /// Output image (.exr, .png or .pfm; also .hdr, .tga); overrides the
    /// Film's filename. EXR and PNG files record pbrs's version, the scene,
    /// spp, integrator, seed and render time (`pbrs img info` shows them).
    #[arg(long, short = 'o', value_name = "FILE")]
    pub outfile: Option<PathBuf>,
    /// Write no metadata into the image: the file then depends on its pixels
    /// alone (byte-identical across runs, thread counts and `pbrs merge`).
    #[arg(long)]
    pub reproducible: bool,
    /// Samples per pixel; overrides the sampler's pixelsamples (pbrt-v4).
    #[arg(long, value_name = "N")]
    pub spp: Option<u32>,
    /// Worker threads; 0 or absent: all cores. The image does not depend on it.
    #[arg(long = "nthreads", visible_alias = "threads", value_name = "N")]
    pub threads: Option<usize>,
    /// Seed for the sampler's scrambling and random dimensions (pbrt-v4).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub seed: u64,
    /// pbrt-v3's quick render: a quarter of each film resolution (at least 1),
    /// one sample per pixel (all samplers but "random", as pbrt-v3), a quarter
    /// of the area and infinite lights' "nsamples" (at least 1).
    #[arg(long)]
    pub quick: bool,
    /// Crop window in NDC: x0 x1 y0 y1 (clamped to [0, 1] and ordered). As in
    /// pbrt-v3, a "cropwindow" given to the Film takes precedence (pbrt-v4
    /// lets the command line win).
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"], allow_negative_numbers = true)]
    pub cropwindow: Option<Vec<f32>>,
    /// Render only pixels x0..x1, y0..y1 of the full image (pbrt-v4); replaces
    /// any crop window.
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"], allow_negative_numbers = true)]
    pub pixelbounds: Option<Vec<i64>>,
    /// Print nothing but errors: no warnings, no progress, no summary.
    #[arg(long, short = 'q')]
    pub quiet: bool,
    /// Print detailed statistics: what was built and skipped, rays, timings.
    #[arg(long)]
    pub stats: bool,
    /// Write the image every --partial-interval seconds while rendering, with
    /// the tiles finished so far (pbrt-v4's flag; pbrt-v4 writes after each
    /// batch of samples instead). Each write is atomic: a temporary file renamed.
    #[arg(long)]
    pub write_partial_images: bool,
    /// Seconds between partial images; implies --write-partial-images.
    #[arg(long, value_name = "SECONDS")]
    pub partial_interval: Option<f64>,
    /// Stream the image to the tev viewer at HOST:PORT while rendering
    /// (pbrt-v4). A lost connection never stops the render.
    #[arg(long, value_name = "HOST:PORT")]
    pub display_server: Option<String>,
    /// pbrt-v3 (glog): verbosity. Accepted; pbrs has no verbose log.
    #[arg(
        long = "v",
        short = 'v',
        value_name = "N",
        help_heading = "Logging (pbrt-v3)"
    )]
    pub verbosity: Option<i32>,
    /// pbrt-v3 (glog): log to standard error. Accepted; pbrs's diagnostics
    /// always go there.
    #[arg(long, help_heading = "Logging (pbrt-v3)")]
    pub logtostderr: bool,
    /// pbrt-v3 (glog): log directory. Accepted; pbrs writes no log files.
    #[arg(long, value_name = "DIR", help_heading = "Logging (pbrt-v3)")]
    pub logdir: Option<PathBuf>,
    /// pbrt-v3 (glog): 0 info, 1 warning, 2 error, 3 fatal. 2 or more hides
    /// warnings; errors are always printed.
    #[arg(long, value_name = "N", help_heading = "Logging (pbrt-v3)")]
    pub minloglevel: Option<i32>,
    /// Render farm: render only tile K of --tiles N (bands of rows, numbered
    /// from 0 as Slurm's SLURM_ARRAY_TASK_ID and Kubernetes'
    /// JOB_COMPLETION_INDEX) into an EXR part for `pbrs merge`. `env` takes
    /// K from SLURM_ARRAY_TASK_ID, else JOB_COMPLETION_INDEX.
    #[arg(
        long,
        value_name = "K",
        requires = "tiles",
        help_heading = "Render farm"
    )]
    pub tile: Option<String>,
    /// Render farm: the number of tiles the frame is split into; `env` takes
    /// it from SLURM_ARRAY_TASK_COUNT.
    #[arg(
        long,
        value_name = "N",
        requires = "tile",
        help_heading = "Render farm"
    )]
    pub tiles: Option<String>,
    /// Render farm: render only sample indices A..B (B excluded) of every
    /// pixel into an EXR part that keeps the film's f64 sums, for `pbrs merge`.
    #[arg(long, num_args = 2, value_names = ["A", "B"], conflicts_with = "tile", help_heading = "Render farm")]
    pub spp_range: Option<Vec<u32>>,
}

impl Args {
    /// Whether warnings are printed.
    pub fn warnings(&self) -> bool {
        !self.quiet && self.minloglevel.is_none_or(|l| l < 2)
    }
}

#[derive(clap::Subcommand, Debug, Clone)]
pub enum Command {
    /// Error against run time: progressive renders compared with a reference.
    Converge(converge::ConvergeArgs),
    /// Merge the parts of a frame (--tile/--tiles or --spp-range renders)
    /// into its image: tiles give the single-machine image bit for bit.
    Merge(merge::MergeArgs),
    /// Golden-image regression tests: render the scenes of DIR and compare
    /// each with DIR/golden/NAME.exr (--update writes the goldens). Exit 0
    /// all pass, 1 a scene regressed, 2 bad input.
    Test(golden::TestArgs),
    /// Image tools: diff, convert, info.
    Img(img::ImgArgs),
}

/// `--nthreads` beyond the machine's cores is clamped to them, with a
/// warning: more threads than cores only add memory (each has its tiles'
/// buffers) and the image does not depend on the count.
fn clamp_threads(args: &mut Args) {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if let Some(n) = args.threads.filter(|&n| n > cores) {
        if args.warnings() {
            eprintln!("warning: --nthreads {n} is more than the machine's {cores} cores: {cores} threads are used");
        }
        args.threads = Some(cores);
    }
}

/// Runs the command line; returns the process exit status.
pub fn main() -> i32 {
    run(std::env::args_os().collect())
}

/// Runs the command line `argv` (program name first).
pub fn run(argv: Vec<OsString>) -> i32 {
    let argv = args::normalize(argv, &Args::command());
    let mut args = Args::parse_from(argv);
    match &args.command {
        Some(Command::Converge(c)) => return converge::run(c),
        Some(Command::Merge(m)) => return merge::run(m),
        Some(Command::Test(t)) => return golden::run(t),
        Some(Command::Img(i)) => return img::run(i),
        None => {}
    }
    clamp_threads(&mut args);
    if args.scenes.is_empty() {
        use std::io::IsTerminal;
        if std::io::stdin().is_terminal() {
            Args::command()
                .error(
                    clap::error::ErrorKind::MissingRequiredArgument,
                    "no scene file given (use `-` to read the scene from standard input)",
                )
                .exit();
        }
        // pbrt-v3 reads standard input when no file is named.
        args.scenes.push(PathBuf::from("-"));
    }
    if [args.check, args.cat, args.toply]
        .iter()
        .filter(|&&b| b)
        .count()
        > 1
    {
        Args::command()
            .error(
                clap::error::ErrorKind::ArgumentConflict,
                "--check, --cat and --toply exclude each other",
            )
            .exit();
    }
    if args.check {
        check::run(&args)
    } else if args.cat || args.toply {
        cat::run(&args)
    } else {
        render::run(&args)
    }
}
