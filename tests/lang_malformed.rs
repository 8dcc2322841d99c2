//! The malformed corpus: every `tests/malformed/*.pbrt` holds one defect and
//! states on its first line where it must be reported:
//! `# error: FILE:LINE: TEXT [| MORE TEXT]`. Each is run through the real binary
//! (`pbrs --check --strict`: exit 1, the location and text on stderr, no
//! panic) and through the library (`load_scene` fails with an error at that
//! place, or, for the defects pbrt-v3 renders through, loads with a warning
//! there that `strictly` makes an error).

use std::path::{Path, PathBuf};
use std::process::Command;

struct Case {
    path: PathBuf,
    /// `tests/malformed/FILE:LINE:`
    location: String,
    texts: Vec<String>,
}

fn cases() -> Vec<Case> {
    let dir = Path::new("tests/malformed");
    let mut out = Vec::new();
    let mut entries: Vec<_> = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(dir))
        .expect("tests/malformed exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "pbrt"))
        .collect();
    entries.sort();
    for p in entries {
        let text = std::fs::read_to_string(&p).unwrap();
        let first = text.lines().next().unwrap_or("");
        let spec = first.strip_prefix("# error: ").unwrap_or_else(|| {
            panic!("{} must start with `# error: FILE:LINE: TEXT`", p.display())
        });
        let mut parts = spec.splitn(3, ':');
        let (file, line, rest) = (
            parts.next().unwrap(),
            parts.next().unwrap(),
            parts.next().unwrap_or(""),
        );
        let line: usize = line
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("bad line number in {}", p.display()));
        let texts = rest
            .split(" | ")
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .collect();
        out.push(Case {
            path: dir.join(p.file_name().unwrap()),
            location: format!("{}:{line}:", dir.join(file).display()),
            texts,
        });
    }
    out
}

#[test]
fn corpus_is_large_enough() {
    assert!(
        cases().len() >= 30,
        "only {} malformed files",
        cases().len()
    );
}

#[test]
fn binary_rejects_every_malformed_file() {
    let mut failures = Vec::new();
    for c in cases() {
        let out = Command::new(env!("CARGO_BIN_EXE_pbrs"))
            .arg("--check")
            .arg("--strict")
            .arg(&c.path)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .env("NO_COLOR", "1")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let mut problems = Vec::new();
        if out.status.code() != Some(1) {
            problems.push(format!("exit status {:?}, expected 1", out.status.code()));
        }
        if stderr.contains("panicked") {
            problems.push("panicked".into());
        }
        // The location must open an error line (`× FILE:LINE:COL: message`).
        let located: Vec<&str> = stderr
            .lines()
            .filter(|l| l.contains(&format!("× {}", c.location)))
            .collect();
        if located.is_empty() {
            problems.push(format!("no error at {}", c.location));
        }
        for t in &c.texts {
            if !stderr.contains(t.as_str()) {
                problems.push(format!("stderr lacks {t:?}"));
            }
        }
        if !problems.is_empty() {
            failures.push(format!(
                "{}: {}\n{stderr}",
                c.path.display(),
                problems.join("; ")
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn library_rejects_every_malformed_file() {
    std::env::set_current_dir(env!("CARGO_MANIFEST_DIR")).unwrap();
    let mut failures = Vec::new();
    for c in cases() {
        match pbrs::loader::load_scene(&c.path).and_then(|s| pbrs::loader::strictly(vec![s])) {
            Ok(_) => failures.push(format!("{}: loaded", c.path.display())),
            Err(f) => {
                assert!(!f.errors.is_empty());
                let msgs: Vec<String> = f.errors.iter().map(|e| e.to_string()).collect();
                if !msgs.iter().any(|m| m.starts_with(&c.location)) {
                    failures.push(format!(
                        "{}: no error at {}: {msgs:?}",
                        c.path.display(),
                        c.location
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
