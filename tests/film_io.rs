//! Image files: round trips, PFM layout, atomic writes.

use pbrs::image::io::{
    check_output_path, parse_pfm, read_exr, read_image, read_pfm, read_png, to_8bit, write_image,
};
use pbrs::image::Image;
use std::fs;
use std::path::{Path, PathBuf};

/// A scratch directory removed when dropped.
struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

fn scratch(name: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("pbrs-film-io-{}-{name}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    Scratch(d)
}

fn test_image() -> Image {
    let (w, h) = (7u32, 5u32);
    let mut data = Vec::new();
    for y in 0..h {
        for x in 0..w {
            data.extend([
                x as f32 * 0.25,
                y as f32 * 1.5 + 0.001,
                (x * y) as f32 * -0.1 + 3.0e-5,
            ]);
        }
    }
    data[3] = 1.0e6;
    data[4] = 1.0e-7;
    Image {
        width: w,
        height: h,
        data,
    }
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn pfm_round_trip_and_layout() {
    let dir = scratch("pfm");
    let img = test_image();
    let p = dir.join("a.pfm");
    write_image(&p, &img).unwrap();
    assert_eq!(read_pfm(&p).unwrap(), img);
    assert_eq!(read_image(&p).unwrap(), img);
    let bytes = fs::read(&p).unwrap();
    let header = b"PF\n7 5\n-1.0\n";
    assert_eq!(&bytes[..header.len()], header);
    assert_eq!(bytes.len(), header.len() + 7 * 5 * 12);
    // First stored row is the bottom row (y = 4).
    let first = f32::from_le_bytes(
        bytes[header.len() + 4..header.len() + 8]
            .try_into()
            .unwrap(),
    );
    assert_eq!(first, img.pixel(0, 4).y);
    // Big-endian and greyscale variants parse too.
    let mut be = b"Pf 2 1 1.0\n".to_vec();
    be.extend(1.5f32.to_be_bytes());
    be.extend(2.5f32.to_be_bytes());
    let g = parse_pfm(&be).unwrap();
    assert_eq!(g.data, vec![1.5, 1.5, 1.5, 2.5, 2.5, 2.5]);
    assert!(parse_pfm(b"PF\n2 2\n-1\n\0\0").is_err());
    assert_eq!(entries(&dir), vec!["a.pfm"]);
}

#[test]
fn exr_round_trip() {
    let dir = scratch("exr");
    let img = test_image();
    let p = dir.join("a.EXR");
    write_image(&p, &img).unwrap();
    assert_eq!(read_exr(&p).unwrap(), img);
    assert_eq!(entries(&dir), vec!["a.EXR"]);
}

#[test]
fn png_round_trip() {
    let dir = scratch("png");
    let mut img = test_image();
    for v in &mut img.data {
        *v = (*v * 0.1).clamp(-1.0, 2.0);
    }
    let p = dir.join("a.png");
    write_image(&p, &img).unwrap();
    let back = read_png(&p).unwrap();
    assert_eq!((back.width, back.height), (img.width, img.height));
    for (a, b) in img.data.iter().zip(&back.data) {
        assert_eq!(to_8bit(*a), to_8bit(*b), "{a} -> {b}");
    }
    assert_eq!(to_8bit(0.0), 0);
    assert_eq!(to_8bit(1.0), 255);
    assert_eq!(to_8bit(5.0), 255);
    assert_eq!(to_8bit(-1.0), 0);
    assert_eq!(to_8bit(0.5), 188); // pbrt-v3: 255 * (1.055 * 0.5^(1/2.4) - 0.055) + 0.5
}

#[test]
fn unknown_extension_is_rejected_without_writing() {
    let dir = scratch("ext");
    for name in ["a.bmp", "a", "a.jpg"] {
        let p = dir.join(name);
        assert!(check_output_path(&p).is_err());
        assert!(write_image(&p, &test_image()).is_err());
    }
    assert!(entries(&dir).is_empty());
    assert!(check_output_path(&dir.join("ok.exr")).is_ok());
    assert!(check_output_path(&dir.join("missing/ok.exr")).is_err());
    assert!(
        entries(&dir).is_empty(),
        "check_output_path leaves nothing behind"
    );
}

#[test]
fn failed_write_leaves_no_partial_file() {
    let dir = scratch("atomic");
    // The target is a directory: the rename fails; the temporary file must go.
    fs::create_dir(dir.join("taken.pfm")).unwrap();
    assert!(write_image(&dir.join("taken.pfm"), &test_image()).is_err());
    assert!(check_output_path(&dir.join("taken.pfm")).is_err());
    assert_eq!(entries(&dir), vec!["taken.pfm"]);
    // A missing directory.
    assert!(write_image(&dir.join("nope/x.exr"), &test_image()).is_err());
    // An inconsistent image does not replace an existing file.
    let p = dir.join("keep.pfm");
    write_image(&p, &test_image()).unwrap();
    let before = fs::read(&p).unwrap();
    let bad = Image {
        width: 3,
        height: 3,
        data: vec![0.0; 5],
    };
    assert!(write_image(&p, &bad).is_err());
    assert_eq!(fs::read(&p).unwrap(), before);
    assert_eq!(entries(&dir), vec!["keep.pfm", "taken.pfm"]);
    // Overwriting an existing file works and is complete.
    let mut img2 = test_image();
    img2.data[0] = 42.0;
    write_image(&p, &img2).unwrap();
    assert_eq!(read_pfm(&p).unwrap(), img2);
}

#[cfg(unix)]
#[test]
fn unwritable_directory() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("ro");
    fs::set_permissions(&*dir, fs::Permissions::from_mode(0o555)).unwrap();
    // Root ignores permissions: only check when the directory really is read-only.
    let really_ro = fs::File::create(dir.join("probe")).is_err();
    if really_ro {
        assert!(check_output_path(&dir.join("a.exr")).is_err());
        assert!(write_image(&dir.join("a.exr"), &test_image()).is_err());
        assert!(entries(&dir).is_empty());
    } else {
        let _ = fs::remove_file(dir.join("probe"));
    }
    fs::set_permissions(&*dir, fs::Permissions::from_mode(0o755)).unwrap();
    // Everywhere: a read-only file system location.
    if Path::new("/proc/self").is_dir() {
        assert!(write_image(Path::new("/proc/pbrs-film-io-test.pfm"), &test_image()).is_err());
        assert!(!Path::new("/proc/pbrs-film-io-test.pfm").exists());
    }
}
