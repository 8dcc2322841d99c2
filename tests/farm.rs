//! Render farm parts: tiles and sample ranges rendered separately and merged
//! give the single-machine image (tiles: byte for byte; sample ranges:
//! within f64 summation-order rounding), and every inconsistent set of parts
//! is refused with an error naming what is wrong.

mod common;

use glam::Vec2;
use pbrs::filters::{BoxFilter, Filter, Gaussian, LanczosSinc, Mitchell, Triangle};
use pbrs::image::io::write_image;
use pbrs::image::Image;
use pbrs::render::driver::{render, render_part, RenderOptions};
use pbrs::render::film::part::{merge, read_part, tile_rect, Part, PartKind};
use pbrs::scene::SceneDescription;
use std::path::{Path, PathBuf};
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pbrs-farm-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The Cornell box at `w`×`h`, `spp` samples, with `filter`.
fn scene(w: u32, h: u32, spp: u32, filter: Filter) -> SceneDescription {
    let mut d = common::load("scenes/cornell-box.pbrt");
    d.film.xresolution = w;
    d.film.yresolution = h;
    d.sampler.pixel_samples = spp;
    d.filter = filter;
    // Short paths keep the renders fast; the image is still noisy and
    // filter-dependent everywhere.
    if let pbrs::scene::IntegratorSettings::Path(pbrs::scene::PathSettings { max_depth, .. }) =
        &mut d.integrator
    {
        *max_depth = 3;
    }
    d
}

fn filters() -> Vec<(&'static str, Filter)> {
    vec![
        (
            "box",
            Filter::Box(BoxFilter {
                radius: Vec2::splat(0.5),
            }),
        ),
        (
            "gaussian",
            Filter::Gaussian(Gaussian::new(Vec2::splat(2.0), 2.0)),
        ),
        (
            "triangle",
            Filter::Triangle(Triangle {
                radius: Vec2::new(2.0, 1.5),
            }),
        ),
        (
            "mitchell",
            Filter::Mitchell(Mitchell {
                radius: Vec2::splat(2.0),
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            }),
        ),
        (
            "sinc",
            Filter::LanczosSinc(LanczosSinc {
                radius: Vec2::splat(4.0),
                tau: 3.0,
            }),
        ),
    ]
}

fn opts() -> RenderOptions {
    RenderOptions {
        threads: Some(2),
        ..Default::default()
    }
}

/// The single-machine render's EXR bytes and image.
fn full(desc: &SceneDescription, dir: &Path) -> (Vec<u8>, Image) {
    let (img, _) = render(desc, &opts(), &|_, _| {}).unwrap();
    let p = dir.join("full.exr");
    write_image(&p, &img).unwrap();
    (std::fs::read(&p).unwrap(), img)
}

fn part(desc: &SceneDescription, kind: PartKind, path: &Path) -> Part {
    render_part(desc, &opts(), kind, path).unwrap();
    read_part(path).unwrap()
}

fn tiles(desc: &SceneDescription, n: u32, dir: &Path) -> Vec<Part> {
    (0..n)
        .map(|k| {
            part(
                desc,
                PartKind::Tile { index: k, count: n },
                &dir.join(format!("tile-{k}-of-{n}.exr")),
            )
        })
        .collect()
}

/// Merges `parts` and returns the EXR bytes written.
fn merged_bytes(parts: &[Part], dir: &Path) -> Vec<u8> {
    let img = merge(parts).unwrap();
    let p = dir.join("merged.exr");
    write_image(&p, &img).unwrap();
    std::fs::read(&p).unwrap()
}

fn merge_err(parts: &[Part]) -> String {
    match merge(parts) {
        Ok(_) => panic!("the merge should have been refused"),
        Err(e) => e,
    }
}

#[test]
fn tiles_merge_to_the_full_render_byte_for_byte_for_every_filter() {
    for (name, f) in filters() {
        let dir = tmp(&format!("tiles-{name}"));
        let desc = scene(40, 30, 4, f);
        let (want, img) = full(&desc, &dir);
        // The image is not trivially flat (the comparison could fail).
        assert!(img.data.iter().any(|&v| v > 0.05), "{name}: image is black");
        for n in [1, 2, 7, 16] {
            let parts = tiles(&desc, n, &dir);
            let got = merged_bytes(&parts, &dir);
            assert!(got == want, "{name}, {n} tiles: merged EXR differs");
            // The parts really are the rows of the split.
            let frame = pbrs::geometry::Bounds2i::new(glam::IVec2::ZERO, glam::IVec2::new(40, 30));
            for (k, p) in parts.iter().enumerate() {
                assert_eq!(p.window, tile_rect(frame, k as u32, n));
            }
        }
    }
}

/// The pixel samplers (02sequence, maxmindist) replay pbrt-v3's tile RNG
/// wherever a farm tile starts: tiles merge to the full render's bytes.
#[test]
fn tiles_merge_byte_for_byte_with_the_pixel_samplers() {
    use pbrs::scene::SamplerKind;
    for kind in [
        SamplerKind::ZeroTwoSequence { dimensions: 4 },
        SamplerKind::MaxMinDist { dimensions: 3 },
    ] {
        let dir = tmp(&format!("tiles-{kind:?}").replace([' ', '{', '}', ':'], ""));
        let mut desc = scene(
            40,
            30,
            4,
            Filter::Gaussian(Gaussian::new(Vec2::splat(2.0), 2.0)),
        );
        desc.sampler.kind = kind;
        let (want, _) = full(&desc, &dir);
        for n in [3, 7] {
            let got = merged_bytes(&tiles(&desc, n, &dir), &dir);
            assert!(got == want, "{kind:?}, {n} tiles: merged EXR differs");
        }
    }
}

#[test]
fn tiles_merge_exactly_with_a_crop_window_and_an_indivisible_resolution() {
    let dir = tmp("crop");
    // 37×23: neither 2, 7 nor 16 divides 23 rows; crop window with
    // fractional edges.
    let mut desc = scene(37, 23, 3, filters()[3].1);
    let (want, _) = full(&desc, &dir);
    for n in [2, 7, 16] {
        assert!(
            merged_bytes(&tiles(&desc, n, &dir), &dir) == want,
            "37x23, {n} tiles"
        );
    }
    desc.film.xresolution = 40;
    desc.film.yresolution = 30;
    desc.film.cropwindow = [0.13, 0.81, 0.27, 0.93];
    let (want, img) = full(&desc, &dir);
    assert_eq!((img.width, img.height), (27, 19));
    for n in [1, 2, 7, 16] {
        let parts = tiles(&desc, n, &dir);
        assert_eq!(parts[0].window.min.y, 9, "tiles are in image coordinates");
        assert!(merged_bytes(&parts, &dir) == want, "crop window, {n} tiles");
    }
}

#[test]
fn a_tile_takes_fewer_samples_than_the_full_render() {
    let dir = tmp("fewer");
    let desc = scene(40, 30, 2, filters()[0].1);
    let s = render_part(
        &desc,
        &opts(),
        PartKind::Tile { index: 3, count: 8 },
        &dir.join("t.exr"),
    )
    .unwrap();
    // Box filter, radius 0.5: the tile's rows plus the margin (one pixel
    // each way), not the whole frame.
    let rows = tile_rect(
        pbrs::geometry::Bounds2i::new(glam::IVec2::ZERO, glam::IVec2::new(40, 30)),
        3,
        8,
    )
    .height() as u64;
    assert!(s.samples <= (rows + 4) * 42 * 2, "{} samples", s.samples);
    assert!(s.samples >= rows * 40 * 2);
}

#[test]
fn sample_ranges_merge_to_the_64_spp_render_within_f64_rounding() {
    for (name, f) in [filters()[2], filters()[3]] {
        let dir = tmp(&format!("ranges-{name}"));
        let desc = scene(40, 30, 64, f);
        let (_, want) = full(&desc, &dir);
        let a = part(
            &desc,
            PartKind::Samples { start: 0, end: 16 },
            &dir.join("a.exr"),
        );
        let b = part(
            &desc,
            PartKind::Samples { start: 16, end: 64 },
            &dir.join("b.exr"),
        );
        // Order of the files does not matter.
        let got = merge(&[b, a]).unwrap();
        assert_eq!((got.width, got.height), (want.width, want.height));
        let mut differ = 0;
        for (g, w) in got.data.iter().zip(&want.data) {
            // The stated bound: the same f32 or its neighbour.
            let ulps = (g.to_bits() as i64 - w.to_bits() as i64).abs();
            assert!(ulps <= 1, "{name}: {g} vs {w} ({ulps} ulp)");
            differ += (ulps != 0) as usize;
        }
        // Most values are bit-identical already.
        assert!(
            differ * 10 < got.data.len(),
            "{name}: {differ} values differ"
        );
        // A 16-spp render is not within the bound (the test can fail).
        let mut d16 = desc.clone();
        d16.sampler.pixel_samples = 16;
        let (_, img16) = full(&d16, &dir);
        assert!(img16
            .data
            .iter()
            .zip(&want.data)
            .any(|(a, b)| (a.to_bits() as i64 - b.to_bits() as i64).abs() > 1));
    }
}

#[test]
fn merge_refuses_gaps_and_overlaps() {
    let dir = tmp("gaps");
    let desc = scene(40, 30, 2, filters()[1].1);
    let mut parts = tiles(&desc, 4, &dir);
    // Gap: tile 2 missing.
    let mut gap = parts.clone();
    gap.remove(2);
    let e = merge_err(&gap);
    assert!(
        e.contains("gap") && e.contains("tile 2 (rows 15..22)"),
        "{e}"
    );
    // Overlap: tile 1 twice.
    let mut dup = parts.clone();
    dup[2] = parts[1].clone();
    dup[2].path = dir.join("copy-of-tile-1.exr");
    let e = merge_err(&dup);
    assert!(
        e.contains("overlap") && e.contains("copy-of-tile-1.exr"),
        "{e}"
    );
    // A tile of another split (2 of 5 in a set of 4).
    let other = part(
        &desc,
        PartKind::Tile { index: 2, count: 5 },
        &dir.join("t2of5.exr"),
    );
    parts[2] = other;
    let e = merge_err(&parts);
    assert!(
        e.contains("t2of5.exr") && e.contains("split differently"),
        "{e}"
    );

    // Sample ranges: a gap and an overlap.
    let desc = scene(40, 30, 8, filters()[1].1);
    let s = |a, b| {
        part(
            &desc,
            PartKind::Samples { start: a, end: b },
            &dir.join(format!("s{a}-{b}.exr")),
        )
    };
    let e = merge_err(&[s(0, 2), s(4, 8)]);
    assert!(e.contains("gap") && e.contains("[2, 4)"), "{e}");
    let e = merge_err(&[s(0, 5)]);
    assert!(e.contains("gap") && e.contains("[5, 8)"), "{e}");
    let e = merge_err(&[s(0, 5), s(4, 8)]);
    assert!(
        e.contains("overlap") && e.contains("s0-5.exr") && e.contains("s4-8.exr"),
        "{e}"
    );
    // Tiles and sample ranges do not mix.
    let t = part(
        &desc,
        PartKind::Tile { index: 0, count: 1 },
        &dir.join("t.exr"),
    );
    let e = merge_err(&[s(0, 8), t]);
    assert!(e.contains("cannot be merged together"), "{e}");
    assert!(merge_err(&[]).contains("no parts"));
}

#[test]
fn merge_refuses_parts_of_another_scene_or_other_settings() {
    let dir = tmp("settings");
    let f = filters()[1].1;
    let base = scene(40, 30, 2, f);
    let tile1 = |d: &SceneDescription, name: &str| {
        part(d, PartKind::Tile { index: 1, count: 2 }, &dir.join(name))
    };
    let t0 = part(
        &base,
        PartKind::Tile { index: 0, count: 2 },
        &dir.join("t0.exr"),
    );
    // The same settings merge (the check can pass).
    assert!(merge(&[t0.clone(), tile1(&base, "ok.exr")]).is_ok());
    let mut other_scene = base.clone();
    other_scene.lights.clear();
    other_scene.shapes.pop();
    let mut spp = base.clone();
    spp.sampler.pixel_samples = 3;
    let mut res = base.clone();
    res.film.xresolution = 41;
    let mut sampler = base.clone();
    sampler.sampler.kind = pbrs::scene::SamplerKind::Random;
    let mut filter = base.clone();
    filter.filter = filters()[2].1;
    let mut crop = base.clone();
    crop.film.cropwindow = [0.0, 0.5, 0.0, 1.0];
    for (d, key) in [
        (&other_scene, "scene"),
        (&spp, "spp"),
        (&res, "resolution"),
        (&sampler, "sampler"),
        (&filter, "filter"),
        (&crop, "pixelbounds"),
    ] {
        let name = format!("other-{key}.exr");
        let e = merge_err(&[t0.clone(), tile1(d, &name)]);
        assert!(
            e.contains(&name) && e.contains(&format!("{key} is")),
            "{key}: {e}"
        );
    }
    // Another seed.
    let p = dir.join("seed.exr");
    render_part(
        &base,
        &RenderOptions { seed: 7, ..opts() },
        PartKind::Tile { index: 1, count: 2 },
        &p,
    )
    .unwrap();
    let e = merge_err(&[t0, read_part(&p).unwrap()]);
    assert!(e.contains("seed is"), "{e}");
}

#[test]
fn truncated_corrupt_and_foreign_files_are_refused_by_name() {
    let dir = tmp("truncated");
    let desc = scene(40, 30, 2, filters()[0].1);
    let p = dir.join("t.exr");
    render_part(&desc, &opts(), PartKind::Tile { index: 0, count: 2 }, &p).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    let cut = dir.join("cut.exr");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let e = read_part(&cut).unwrap_err();
    assert!(e.contains("cut.exr") && e.contains("truncated"), "{e}");
    let mut bad = bytes.clone();
    for b in &mut bad[bytes.len() - 200..] {
        *b = !*b;
    }
    let bad_p = dir.join("corrupt.exr");
    std::fs::write(&bad_p, &bad).unwrap();
    assert!(read_part(&bad_p).unwrap_err().contains("corrupt.exr"));
    // An ordinary image is not a part.
    let plain = dir.join("plain.exr");
    write_image(&plain, &Image::new(4, 4)).unwrap();
    let e = read_part(&plain).unwrap_err();
    assert!(
        e.contains("plain.exr") && e.contains("not a pbrs farm part"),
        "{e}"
    );
    assert!(read_part(&dir.join("absent.exr"))
        .unwrap_err()
        .contains("absent.exr"));
}

fn pbrs() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_pbrs"));
    c.arg("--quiet");
    c
}

fn merge_cmd() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_pbrs"));
    c.args(["merge", "--quiet"]);
    c
}

fn run_ok(c: &mut Command) {
    let o = c.output().unwrap();
    assert!(
        o.status.success(),
        "{c:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn command_line_tiles_and_merge_give_the_full_render_and_refuse_to_overwrite() {
    let dir = tmp("cli");
    let scene = common::repo().join("scenes/cornell-box.pbrt");
    let common_args = |c: &mut Command| {
        c.arg(&scene).args([
            "--spp",
            "2",
            "--pixelbounds",
            "0,48,0,36",
            "--nthreads",
            "2",
        ]);
    };
    let mut c = pbrs();
    common_args(&mut c);
    // The merge writes no render metadata: the single render leaves it out.
    run_ok(
        c.arg("--reproducible")
            .arg("--outfile")
            .arg(dir.join("full.exr")),
    );
    let mut parts = Vec::new();
    for k in 0..3 {
        let p = dir.join(format!("part-{k}.exr"));
        let mut c = pbrs();
        common_args(&mut c);
        if k == 1 {
            // `env`: the index from Slurm's variable.
            c.args(["--tile", "env", "--tiles", "3"])
                .env("SLURM_ARRAY_TASK_ID", "1");
        } else {
            c.args(["--tile", &k.to_string(), "--tiles", "3"]);
        }
        run_ok(c.arg("--outfile").arg(&p));
        parts.push(p);
    }
    let out = dir.join("merged.exr");
    run_ok(merge_cmd().arg(&out).args(parts.iter().rev()));
    assert!(std::fs::read(&out).unwrap() == std::fs::read(dir.join("full.exr")).unwrap());
    // PNG from the merge equals the full render's PNG.
    let mut c = pbrs();
    common_args(&mut c);
    run_ok(
        c.arg("--reproducible")
            .arg("--outfile")
            .arg(dir.join("full.png")),
    );
    run_ok(merge_cmd().arg(dir.join("merged.png")).args(&parts));
    assert!(
        std::fs::read(dir.join("merged.png")).unwrap()
            == std::fs::read(dir.join("full.png")).unwrap()
    );
    // An existing output is not replaced without --force.
    let before = std::fs::read(&out).unwrap();
    let o = merge_cmd().arg(&out).args(&parts[..2]).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("exists") && err.contains("--force"), "{err}");
    // With --force, a gap is still refused and the output kept.
    let o = merge_cmd()
        .arg("--force")
        .arg(&out)
        .args(&parts[..2])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("tile 2"));
    assert_eq!(std::fs::read(&out).unwrap(), before);
    run_ok(merge_cmd().arg("--force").arg(&out).args(&parts));
    // Bad part requests are usage errors.
    for bad in [
        &["--tile", "3", "--tiles", "3"][..],
        &["--tile", "0", "--tiles", "999"],
        &["--tile", "env", "--tiles", "2"],
        &["--spp-range", "1", "1"],
        &["--spp-range", "0", "3"],
    ] {
        let mut c = pbrs();
        common_args(&mut c);
        let o = c
            .args(bad)
            .env_remove("SLURM_ARRAY_TASK_ID")
            .env_remove("JOB_COMPLETION_INDEX")
            .arg("--outfile")
            .arg(dir.join("bad.exr"))
            .output()
            .unwrap();
        assert_ne!(o.status.code(), Some(0), "{bad:?}");
        assert!(!dir.join("bad.exr").exists());
    }
}
