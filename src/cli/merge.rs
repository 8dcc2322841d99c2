//! `pbrs merge OUT PART...`: the image of a frame rendered in parts (tiles
//! or sample ranges, see [`crate::render::film::part`]).

use crate::image::io::{check_output_path, write_image};
use crate::render::film::part::{merge, read_part};
use std::path::PathBuf;
use std::time::Instant;

/// Merge the parts of a frame rendered with --tile/--tiles or --spp-range.
#[derive(clap::Args, Debug, Clone)]
pub struct MergeArgs {
    /// The merged image (.exr, .png or .pfm).
    #[arg(value_name = "OUT")]
    pub out: PathBuf,
    /// The part files (EXR), in any order: all N tiles of one split, or
    /// sample ranges covering 0..spp.
    #[arg(value_name = "PART", required = true)]
    pub parts: Vec<PathBuf>,
    /// Replace OUT if it exists (otherwise an existing OUT is an error).
    #[arg(long, short = 'f')]
    pub force: bool,
    /// Print nothing but errors.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

pub fn run(args: &MergeArgs) -> i32 {
    let t0 = Instant::now();
    match merge_files(args) {
        Ok(()) => {
            if !args.quiet {
                eprintln!(
                    "{}: merged {} parts in {:.3} s",
                    args.out.display(),
                    args.parts.len(),
                    t0.elapsed().as_secs_f64()
                );
            }
            0
        }
        Err(e) => {
            eprintln!("error: {e}");
            eprintln!("merge: nothing was written");
            1
        }
    }
}

fn merge_files(args: &MergeArgs) -> Result<(), String> {
    let out = &args.out;
    check_output_path(out)?;
    if !args.force && out.exists() {
        return Err(format!(
            "{} exists; pass --force to replace it",
            out.display()
        ));
    }
    let same = |p: &PathBuf| match (p.canonicalize(), out.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    if let Some(p) = args.parts.iter().find(|p| same(p)) {
        return Err(format!("{} is both the output and a part", p.display()));
    }
    let parts = args
        .parts
        .iter()
        .map(|p| read_part(p))
        .collect::<Result<Vec<_>, _>>()?;
    let image = merge(&parts)?;
    write_image(out, &image)
}
