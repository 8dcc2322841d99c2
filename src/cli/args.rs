//! argv as pbrt writes it, rewritten for clap before parsing.
//!
//! pbrt-v3 (main/pbrt.cpp) takes each flag with one or two dashes
//! (`-nthreads 4`, `--nthreads 4`) and some as `--flag=value`; pbrt-v4
//! (util/args.h) takes `-flag`/`--flag` and `=value` for every flag, and
//! `--cropwindow`/`--pixelbounds` as one comma-separated `x0,x1,y0,y1`.
//! clap knows `--flag value` and `--flag=value`, so this pass only turns
//! `-flag[=value]` into `--flag[=value]` for the long names clap declares
//! (taken from the command itself, so `--help` and the parser stay the one
//! source of truth) and splits the comma form into four values.

use clap::Command;
use std::ffi::OsString;

/// Flags whose four values pbrt-v4 writes as one `x0,x1,y0,y1`.
const FOUR_VALUE_FLAGS: &[&str] = &["cropwindow", "pixelbounds"];

/// Returns argv (program name first) with pbrt's spellings made clap's.
/// A subcommand's arguments (e.g. `pbrs converge ...`) and everything after
/// `--` are left as they are.
pub fn normalize(argv: Vec<OsString>, cmd: &Command) -> Vec<OsString> {
    let Some(first) = argv.get(1).and_then(|a| a.to_str()) else {
        return argv;
    };
    if cmd.get_subcommands().any(|s| s.get_name() == first) {
        return argv;
    }
    let longs: Vec<&str> = cmd
        .get_arguments()
        .flat_map(|a| {
            a.get_long()
                .into_iter()
                .chain(a.get_all_aliases().into_iter().flatten())
        })
        .chain(["help", "version"])
        .collect();
    let mut out = Vec::with_capacity(argv.len() + 4);
    let mut it = argv.into_iter();
    out.extend(it.next());
    let mut split_next = false;
    while let Some(arg) = it.next() {
        let Some(s) = arg.to_str() else {
            out.push(arg);
            split_next = false;
            continue;
        };
        if s == "--" {
            out.push(arg);
            out.extend(it);
            break;
        }
        if split_next {
            split_next = false;
            if s.contains(',') {
                out.extend(s.split(',').map(OsString::from));
                continue;
            }
        }
        // `-name` or `--name`, maybe `=value`.
        let body = s
            .strip_prefix("--")
            .or_else(|| s.strip_prefix('-'))
            .filter(|b| !b.is_empty());
        let Some(body) = body else {
            out.push(arg);
            continue;
        };
        let (name, value) = match body.split_once('=') {
            Some((n, v)) => (n, Some(v)),
            None => (body, None),
        };
        // A single dash before one letter is clap's short flag (`-o`, `-q`);
        // before a number it is a negative value.
        let single = !s.starts_with("--");
        if !longs.contains(&name) || (single && name.len() == 1 && value.is_none()) {
            out.push(arg);
            continue;
        }
        if FOUR_VALUE_FLAGS.contains(&name) {
            out.push(OsString::from(format!("--{name}")));
            match value {
                Some(v) => out.extend(v.split(',').map(OsString::from)),
                None => split_next = true,
            }
            continue;
        }
        out.push(match value {
            Some(v) => OsString::from(format!("--{name}={v}")),
            None => OsString::from(format!("--{name}")),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    fn norm(args: &[&str]) -> Vec<String> {
        let argv = std::iter::once("pbrs")
            .chain(args.iter().copied())
            .map(OsString::from)
            .collect();
        normalize(argv, &crate::cli::Args::command())
            .into_iter()
            .skip(1)
            .map(|a| a.into_string().unwrap())
            .collect()
    }

    #[test]
    fn pbrt_spellings_become_clap_ones() {
        assert_eq!(
            norm(&["-nthreads", "4", "a.pbrt"]),
            ["--nthreads", "4", "a.pbrt"]
        );
        assert_eq!(norm(&["-outfile=x.exr"]), ["--outfile=x.exr"]);
        assert_eq!(norm(&["--nthreads=2"]), ["--nthreads=2"]);
        assert_eq!(
            norm(&["-quick", "-quiet", "-cat"]),
            ["--quick", "--quiet", "--cat"]
        );
        assert_eq!(norm(&["-help"]), ["--help"]);
        assert_eq!(
            norm(&["-cropwindow", "0", "0.5", "0", "1"]),
            ["--cropwindow", "0", "0.5", "0", "1"]
        );
        assert_eq!(
            norm(&["--cropwindow", "0,0.5,0,1", "s.pbrt"]),
            ["--cropwindow", "0", "0.5", "0", "1", "s.pbrt"]
        );
        assert_eq!(
            norm(&["--pixelbounds=0,4,2,8"]),
            ["--pixelbounds", "0", "4", "2", "8"]
        );
        // Short flags, negative numbers, unknown words, stdin are untouched.
        assert_eq!(
            norm(&["-q", "-o", "x.png", "-"]),
            ["-q", "-o", "x.png", "-"]
        );
        assert_eq!(norm(&["-v", "2"]), ["-v", "2"]);
        assert_eq!(norm(&["-frobnicate"]), ["-frobnicate"]);
        assert_eq!(norm(&["--", "-quick"]), ["--", "-quick"]);
        // A subcommand keeps its own arguments.
        assert_eq!(
            norm(&["converge", "s.pbrt", "-spp-max", "4"]),
            ["converge", "s.pbrt", "-spp-max", "4"]
        );
    }
}
