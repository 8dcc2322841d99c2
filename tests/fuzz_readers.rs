//! A deterministic fuzzer for every reader of files pbrs takes, run by
//! `cargo test` on stable Rust in bounded time (cargo-fuzz, which needs a
//! nightly toolchain, is in `fuzz/`). The seed corpus is committed: the
//! small files of `scenes/`, `tests/inputs/` and `tests/malformed/` (valid
//! and malformed). Each reader gets every seed of its kind mutated by a
//! seeded generator (bit flips, bytes and 32-bit words set to boundary
//! values, cuts, duplicated and deleted runs, numbers in text replaced by
//! extremes) for [`ITERATIONS`] rounds or [`SECONDS_PER_READER`] seconds,
//! whichever ends first; any panic, even one a reader catches itself, fails
//! the test with the seed file and round that reproduce it.
//! `PBRS_FUZZ_ITERATIONS` and `PBRS_FUZZ_SECONDS` raise the bounds for a
//! longer local run.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

const ITERATIONS: usize = 300;
const SECONDS_PER_READER: f64 = 20.0;

static PANICS: AtomicUsize = AtomicUsize::new(0);

/// xorshift64*: the mutations are the same on every machine.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const WORDS: [u32; 8] = [
    0,
    1,
    0x7f,
    0xff,
    0xffff,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
];
const NUMBERS: [&str; 10] = [
    "0",
    "-1",
    "1e30",
    "-1e30",
    "1e-30",
    "4294967295",
    "2147483648",
    "99999999999",
    "nan",
    "3.4e38",
];

/// One to four mutations of `seed`.
fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        if b.is_empty() {
            b.push(rng.next() as u8);
            continue;
        }
        let i = rng.below(b.len());
        match rng.below(8) {
            0 => b[i] ^= 1 << rng.below(8),
            1 => b[i] = [0u8, 0xff, 0x7f, 0x80][rng.below(4)],
            2 => {
                let w = WORDS[rng.below(WORDS.len())].to_le_bytes();
                let be = rng.below(2) == 1;
                for (k, &x) in w.iter().enumerate() {
                    if let Some(v) = b.get_mut(i + k) {
                        *v = if be { w[3 - k] } else { x };
                    }
                }
            }
            3 => b.truncate(i),
            4 => {
                let n = rng.below(64).min(b.len() - i);
                let run: Vec<u8> = b[i..i + n].to_vec();
                let at = rng.below(b.len());
                b.splice(at..at, run);
            }
            5 => {
                let n = rng.below(64).min(b.len() - i);
                b.drain(i..i + n);
            }
            _ => {
                // A number in text replaced by an extreme one.
                let is_num = |c: u8| c.is_ascii_digit() || c == b'.' || c == b'-' || c == b'e';
                if let Some(start) = (i..b.len()).find(|&k| b[k].is_ascii_digit()) {
                    let end = (start..b.len()).find(|&k| !is_num(b[k])).unwrap_or(b.len());
                    let n = NUMBERS[rng.below(NUMBERS.len())].as_bytes().to_vec();
                    b.splice(start..end, n);
                }
            }
        }
    }
    b
}

/// Small files under `dirs` whose names end with one of `exts`.
fn seeds(exts: &[&str]) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    let mut stack: Vec<PathBuf> = ["scenes", "tests/inputs", "tests/malformed"]
        .iter()
        .map(|d| root.join(d))
        .collect();
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if exts
                .iter()
                .any(|x| p.to_string_lossy().to_ascii_lowercase().ends_with(x))
                && e.metadata().is_ok_and(|m| m.len() <= 64 << 10)
            {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Runs `read` on every mutation of every seed; the failures found.
fn fuzz(name: &str, exts: &[&str], read: impl Fn(&Path, &[u8])) -> Vec<String> {
    std::panic::set_hook(Box::new(|_| {
        PANICS.fetch_add(1, Ordering::SeqCst);
    }));
    let files = seeds(exts);
    assert!(!files.is_empty(), "{name}: no seed files");
    let iterations = env_or("PBRS_FUZZ_ITERATIONS", ITERATIONS);
    let budget = Duration::from_secs_f64(env_or("PBRS_FUZZ_SECONDS", SECONDS_PER_READER));
    let start = Instant::now();
    let mut failures = Vec::new();
    'rounds: for round in 0..iterations {
        for (k, f) in files.iter().enumerate() {
            if start.elapsed() > budget {
                break 'rounds;
            }
            let seed = std::fs::read(f).unwrap();
            let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ ((round as u64) << 20) ^ k as u64);
            let bytes = if round == 0 {
                seed
            } else {
                mutate(&seed, &mut rng)
            };
            let before = PANICS.load(Ordering::SeqCst);
            let t = Instant::now();
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| read(f, &bytes)));
            if r.is_err() || PANICS.load(Ordering::SeqCst) != before {
                failures.push(format!("{name}: {} round {round}: panicked", f.display()));
            }
            if t.elapsed() > Duration::from_secs(10) {
                failures.push(format!(
                    "{name}: {} round {round}: took {:.1} s",
                    f.display(),
                    t.elapsed().as_secs_f64()
                ));
            }
        }
    }
    let _ = std::panic::take_hook();
    failures
}

/// The readers, one test each (run one at a time: the panic hook is global).
fn check(name: &str, exts: &[&str], read: impl Fn(&Path, &[u8])) {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _g = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let failures = fuzz(name, exts, read);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn images() {
    check(
        "image",
        &[".png", ".tga", ".exr", ".pfm", ".hdr"],
        |p, b| {
            let _ = pbrs::loader::image::decode_image(b, p);
        },
    );
}

#[test]
fn meshes() {
    check("mesh", &[".ply", ".obj", ".gltf", ".glb"], |p, b| {
        let ext = p.extension().unwrap().to_string_lossy().to_string();
        match ext.as_str() {
            "ply" => {
                let _ = pbrs::loader::ply::read_ply(b);
            }
            "obj" => {
                let _ = pbrs::loader::meshfile::read_obj(b);
            }
            _ => {
                let dir = p.parent().unwrap();
                let load = |q: &Path| std::fs::read(dir.join(q)).map_err(|e| e.to_string());
                let _ = pbrs::loader::meshfile::read_gltf(b, dir, &load);
            }
        }
    });
}

#[test]
fn spectra_bsdfs_and_lenses() {
    check(
        "spd, bsdf, lens",
        &[".spd", ".bsdf", ".dat"],
        |p, b| match p.extension().unwrap().to_str().unwrap() {
            "spd" => {
                let _ = pbrs::loader::spd::parse(&String::from_utf8_lossy(b));
            }
            "bsdf" => {
                let _ = pbrs::loader::fourier::read_bsdf(b, "fuzz");
            }
            _ => {
                let _ = pbrs::cameras::realistic::parse_lens_file(&String::from_utf8_lossy(b));
            }
        },
    );
}

#[test]
fn scene_text() {
    check("scene", &[".pbrt"], |p, b| {
        // Mutated in memory, read with the seed's directory for Includes
        // and meshes, built but not rendered.
        let text = String::from_utf8_lossy(b);
        let _ = pbrs::loader::load_scene_str(&text, p);
    });
}

#[test]
fn farm_parts() {
    let dir = std::env::temp_dir().join(format!("pbrs-fuzz-parts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("part.exr");
    check("farm part", &[".exr"], |_, b| {
        std::fs::write(&path, b).unwrap();
        let _ = pbrs::render::film::part::read_part(&path);
    });
    let _ = std::fs::remove_dir_all(&dir);
}
