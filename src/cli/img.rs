//! `pbrs img diff|convert|info`: image tools for EXR, PFM, PNG, TGA and HDR
//! files. Exit status 0 success (diff: within the tolerances), 1 a diff
//! beyond them, 2 bad input (unreadable, truncated or corrupt files, images
//! of different sizes, bad arguments). Outputs are written atomically.

use crate::image::compare::{block_error, compare, false_colour_difference, relative_mse, rmse};
use crate::image::io::{check_output_path, format_for_path, write_image};
use crate::image::meta::{read_any, ImageFile};
use crate::image::verdict::{mean_difference, nonfinite_pixels};
use crate::image::Image;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug, Clone)]
pub struct ImgArgs {
    #[command(subcommand)]
    pub command: ImgCommand,
}

#[derive(clap::Subcommand, Debug, Clone)]
pub enum ImgCommand {
    /// Compare two images: MSE, relative MSE, mean absolute and largest
    /// differences, channel means, 8×8 block error, non-finite pixels.
    Diff(DiffArgs),
    /// Convert between EXR, PFM, HDR, PNG and TGA (by extension).
    Convert(ConvertArgs),
    /// Resolution, channels, statistics and pbrs metadata of images.
    Info(InfoArgs),
}

#[derive(clap::Args, Debug, Clone)]
pub struct DiffArgs {
    /// The image to judge.
    pub a: PathBuf,
    /// The reference (the denominator of the relative metrics).
    pub b: PathBuf,
    /// Largest relative MSE that passes (exit 0 within, 1 beyond). Without
    /// --tol and --mean-tol any differing pixel value exits 1.
    #[arg(long, value_name = "X")]
    pub tol: Option<f64>,
    /// Largest relative difference of the per-channel means that passes.
    #[arg(long, value_name = "X")]
    pub mean_tol: Option<f64>,
    /// Write a false-colour image of the per-pixel relative difference
    /// (black 0, blue, green, yellow, red, white at 0.5 or more).
    #[arg(long, value_name = "FILE")]
    pub error_image: Option<PathBuf>,
}

#[derive(clap::Args, Debug, Clone)]
pub struct ConvertArgs {
    pub input: PathBuf,
    pub output: PathBuf,
    /// Scale by 2^EV.
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "EV",
        allow_negative_numbers = true
    )]
    pub exposure: f32,
    /// 8-bit outputs: encode v^(1/G) instead of the sRGB curve.
    #[arg(long, value_name = "G")]
    pub gamma: Option<f32>,
    /// Clamp values to [0, 1].
    #[arg(long)]
    pub clamp: bool,
    /// Keep pixels x0..x1, y0..y1 (x1, y1 excluded).
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"])]
    pub crop: Option<Vec<u32>>,
    /// Flip top to bottom.
    #[arg(long)]
    pub flip: bool,
}

#[derive(clap::Args, Debug, Clone)]
pub struct InfoArgs {
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

pub fn run(args: &ImgArgs) -> i32 {
    let r = match &args.command {
        ImgCommand::Diff(d) => diff(d),
        ImgCommand::Convert(c) => convert(c).map(|()| 0),
        ImgCommand::Info(i) => Ok(info(i)),
    };
    r.unwrap_or_else(|e| {
        eprintln!("error: {e}");
        2
    })
}

fn read(path: &Path) -> Result<ImageFile, String> {
    read_any(path)
}

/// Non-finite values as 0, for metrics over the finite part.
fn finite(img: &Image) -> Image {
    Image {
        data: img
            .data
            .iter()
            .map(|&v| if v.is_finite() { v } else { 0.0 })
            .collect(),
        ..img.clone()
    }
}

fn diff(d: &DiffArgs) -> Result<i32, String> {
    if let Some(e) = &d.error_image {
        check_output_path(e)?;
    }
    let (fa, fb) = (read(&d.a)?, read(&d.b)?);
    let (a, b) = (&fa.image, &fb.image);
    if (a.width, a.height) != (b.width, b.height) {
        return Err(format!(
            "{} is {}×{} but {} is {}×{}: images of different sizes",
            d.a.display(),
            a.width,
            a.height,
            d.b.display(),
            b.width,
            b.height
        ));
    }
    let grey = |f: &ImageFile| f.channels == "Y" || f.channels.starts_with("Grayscale");
    let (ga, gb) = (grey(&fa), grey(&fb));
    if ga != gb {
        return Err(format!(
            "{} has channels {} but {} has {}: a grey and a colour image",
            d.a.display(),
            fa.channels,
            d.b.display(),
            fb.channels
        ));
    }
    let (na, nb) = (nonfinite_pixels(a), nonfinite_pixels(b));
    let (a, b) = (finite(a), finite(b));
    let n = a.data.len().max(1) as f64;
    let (mut mae, mut max) = (0.0f64, 0.0f64);
    for (x, y) in a.data.iter().zip(&b.data) {
        let e = (*x as f64 - *y as f64).abs();
        mae += e;
        max = max.max(e);
    }
    let c = compare(&a, &b);
    let rel = relative_mse(&a, &b);
    let md = mean_difference(&c);
    println!("A: {} ({}×{})", d.a.display(), a.width, a.height);
    println!("B: {} (reference)", d.b.display());
    println!("MSE            {:.6e}", rmse(&a, &b).powi(2));
    println!("relative MSE   {rel:.6e}");
    println!("mean |A−B|     {:.6e}", mae / n);
    println!("max |A−B|      {max:.6e}");
    println!("block error    {:.6e}", block_error(&a, &b));
    println!(
        "means A        {:.6} {:.6} {:.6}",
        c.mean_a[0], c.mean_a[1], c.mean_a[2]
    );
    println!(
        "means B        {:.6} {:.6} {:.6}",
        c.mean_r[0], c.mean_r[1], c.mean_r[2]
    );
    println!("mean difference {md:.6e} (largest relative, per channel)");
    println!("non-finite     A {na}, B {nb}");
    if let Some(e) = &d.error_image {
        write_image(e, &false_colour_difference(&a, &b))?;
    }
    let within = if d.tol.is_none() && d.mean_tol.is_none() {
        max == 0.0
    } else {
        d.tol.is_none_or(|t| rel <= t) && d.mean_tol.is_none_or(|t| md <= t)
    };
    let ok = within && na == 0 && nb == 0;
    println!("{}", if ok { "within tolerance" } else { "DIFFERENT" });
    Ok(if ok { 0 } else { 1 })
}

fn convert(c: &ConvertArgs) -> Result<(), String> {
    let out_format = format_for_path(&c.output)?;
    check_output_path(&c.output)?;
    if let Some(g) = c.gamma {
        if !(g > 0.0 && g.is_finite()) {
            return Err(format!("--gamma must be a number > 0, not {g}"));
        }
    }
    if !c.exposure.is_finite() {
        return Err("--exposure must be finite".into());
    }
    let f = read(&c.input)?;
    let mut img = f.image;
    if let Some(cr) = &c.crop {
        let (x0, x1, y0, y1) = (cr[0], cr[1], cr[2], cr[3]);
        if x0 >= x1 || y0 >= y1 || x1 > img.width || y1 > img.height {
            return Err(format!(
                "--crop {x0} {x1} {y0} {y1} is not within {} ({}×{}; x0 < x1 ≤ width, y0 < y1 ≤ height)",
                c.input.display(),
                img.width,
                img.height
            ));
        }
        let mut out = Image::new(x1 - x0, y1 - y0);
        for y in y0..y1 {
            for x in x0..x1 {
                out.set_pixel(x - x0, y - y0, img.pixel(x, y));
            }
        }
        img = out;
    }
    if c.flip {
        let row = 3 * img.width as usize;
        let rows: Vec<&[f32]> = img.data.chunks_exact(row).rev().collect();
        img.data = rows.concat();
    }
    let scale = 2f32.powf(c.exposure);
    let bad = nonfinite_pixels(&img);
    let blacken = out_format.is_8bit() || out_format == crate::image::io::ImageFormat::Hdr;
    for px in img.data.chunks_exact_mut(3) {
        if blacken && px.iter().any(|v| !v.is_finite()) {
            px.fill(0.0);
            continue;
        }
        for v in px.iter_mut() {
            *v *= scale;
            if c.clamp {
                *v = v.clamp(0.0, 1.0);
            }
            if let (Some(g), true) = (c.gamma, out_format.is_8bit()) {
                // The 8-bit writers apply the sRGB curve: hand them the value
                // whose sRGB encoding is v^(1/g).
                *v = crate::scene::image::srgb_to_linear(v.max(0.0).powf(1.0 / g).min(1.0));
            }
        }
    }
    if bad > 0 {
        eprintln!(
            "warning: {}: {bad} pixels with NaN or infinite values{}",
            c.input.display(),
            if blacken { " (written as black)" } else { "" }
        );
    }
    write_image(&c.output, &img)
}

fn info(i: &InfoArgs) -> i32 {
    let mut status = 0;
    for p in &i.files {
        match read(p) {
            Ok(f) => print_info(p, &f),
            Err(e) => {
                eprintln!("error: {e}");
                status = 2;
            }
        }
    }
    status
}

fn print_info(p: &Path, f: &ImageFile) {
    let img = &f.image;
    println!("{}", p.display());
    println!(
        "  {} {}×{}, channels {}",
        f.format.name(),
        img.width,
        img.height,
        f.channels
    );
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut sum = [0.0f64; 3];
    let (mut lum, mut n) = (0.0f64, 0usize);
    for px in img.data.chunks_exact(3) {
        if px.iter().any(|v| !v.is_finite()) {
            continue;
        }
        n += 1;
        for c in 0..3 {
            let v = px[c] as f64;
            lo[c] = lo[c].min(v);
            hi[c] = hi[c].max(v);
            sum[c] += v;
        }
        lum += 0.2126 * px[0] as f64 + 0.7152 * px[1] as f64 + 0.0722 * px[2] as f64;
    }
    let nn = n.max(1) as f64;
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        println!(
            "  {name}: min {:.6} max {:.6} mean {:.6}",
            lo[c],
            hi[c],
            sum[c] / nn
        );
    }
    println!("  average luminance {:.6}", lum / nn);
    println!("  non-finite pixels {}", img.data.len() / 3 - n);
    if f.format.is_8bit() {
        println!("  (8-bit values decoded from sRGB to linear)");
    }
    for (k, v) in &f.metadata {
        println!("  {k}: {v}");
    }
}
