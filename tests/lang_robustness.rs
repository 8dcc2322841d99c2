//! A deterministic, in-tree cousin of the cargo-fuzz target (fuzz/): mutated
//! versions of every scene and malformed file must load or fail with located
//! errors, never panic. Runs on stable as part of `cargo test`.

use pbrs::lang::FileLoader;
use pbrs::loader::{load_scene_with, ply::read_ply};
use std::path::{Path, PathBuf};

struct Served(Vec<u8>);

impl FileLoader for Served {
    fn load(&self, _: &Path) -> Result<Vec<u8>, String> {
        Ok(self.0.clone())
    }
}

fn inputs() -> Vec<Vec<u8>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<PathBuf> = Vec::new();
    for dir in ["scenes", "tests/malformed"] {
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "pbrt" || x == "inc") {
                files.push(p);
            }
        }
    }
    files.sort();
    files.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

const PLY: &[u8] = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

const TOKENS: &[&[u8]] = &[
    b"[",
    b"]",
    b"\"",
    b"#",
    b"\n",
    b" 1e999 ",
    b" nan ",
    b"Include \"x\"\n",
    b"AttributeEnd\n",
    b"ObjectEnd\n",
    b"\"point P\" [0 0 0]",
    b"Shape \"plymesh\" \"string filename\" \"m.ply\"\n",
    b"\\",
];

/// `FILE:LINE:COL: ` at the start of a message.
fn located(msg: &str) -> bool {
    let mut parts = msg.splitn(4, ':');
    let (_, line, col, rest) = (parts.next(), parts.next(), parts.next(), parts.next());
    let num =
        |s: Option<&str>| s.is_some_and(|s| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()));
    num(line) && num(col) && rest.is_some_and(|r| r.starts_with(' '))
}

#[test]
fn mutated_inputs_never_panic() {
    let mut state: u64 = 0x9E3779B97F4A7C15;
    let mut rnd = move |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n.max(1) as u64) as usize
    };
    let inputs = inputs();
    let mut runs = 0;
    for base in &inputs {
        for _ in 0..40 {
            let mut d = base.clone();
            for _ in 0..1 + rnd(4) {
                let at = rnd(d.len() + 1);
                match rnd(4) {
                    0 => d.truncate(at),
                    1 if at < d.len() => d[at] ^= 1 << rnd(8),
                    2 => {
                        let t = TOKENS[rnd(TOKENS.len())];
                        d.splice(at..at, t.iter().copied());
                    }
                    _ => {
                        let end = (at + rnd(64)).min(d.len());
                        d.drain(at..end);
                    }
                }
            }
            let mut ply = PLY.to_vec();
            let cut = rnd(ply.len() + 1);
            ply.truncate(cut.max(ply.len() - rnd(20)));
            if let Ok(text) = std::str::from_utf8(&d) {
                match load_scene_with(text, Path::new("fuzz.pbrt"), Box::new(Served(ply.clone()))) {
                    Ok(_) => {}
                    Err(f) => {
                        assert!(!f.errors.is_empty());
                        for e in f.errors.iter().chain(&f.warnings) {
                            assert!(located(&e.to_string()), "not located: {e}");
                        }
                    }
                }
            }
            let _ = read_ply(&d);
            let _ = read_ply(&ply);
            runs += 1;
        }
    }
    assert!(runs > 1000, "{runs}");
}
