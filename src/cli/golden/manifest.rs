//! `DIR/golden.toml`: which scenes `pbrs test DIR` checks and how. Every key
//! is optional; without the file (or without `[[scene]]` tables) every
//! `.pbrt` file at the top level of DIR is a scene, with the defaults.
//!
//! ```toml
//! spp = 16                 # defaults for every scene (the scene's own when absent)
//! resolution = [64, 64]
//! tolerance = 2.0          # relative MSE and block error, × their expected noise
//! mean_tolerance = 6.0     # image means, in standard deviations of their noise
//!
//! [[scene]]
//! file = "box.pbrt"        # relative to DIR
//! name = "box"             # golden/NAME.exr (default: the file's path, '/' as '-')
//! spp = 64                 # and resolution, tolerance, mean_tolerance
//! ```
//!
//! Errors name the file, the line and column, and the key.

use std::path::{Path, PathBuf};
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// Default tolerance on relative MSE and block error, as multiples of their
/// expected values under noise alone.
pub const DEFAULT_TOLERANCE: f64 = 2.0;
/// Default tolerance on the per-channel image means, in standard deviations.
pub const DEFAULT_MEAN_TOLERANCE: f64 = 6.0;

/// How one scene is rendered and judged.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub spp: Option<u32>,
    pub resolution: Option<(u32, u32)>,
    pub tolerance: f64,
    pub mean_tolerance: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            spp: None,
            resolution: None,
            tolerance: DEFAULT_TOLERANCE,
            mean_tolerance: DEFAULT_MEAN_TOLERANCE,
        }
    }
}

/// One scene to check.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneEntry {
    /// Path of the scene file.
    pub file: PathBuf,
    /// Name of its golden (`golden/NAME.exr`) and of its line in the table.
    pub name: String,
    pub settings: Settings,
}

/// The scenes of `dir`, from `dir/golden.toml` if there is one.
pub fn scenes(dir: &Path) -> Result<Vec<SceneEntry>, String> {
    if !dir.is_dir() {
        return Err(format!("{}: not a directory", dir.display()));
    }
    let toml_path = dir.join("golden.toml");
    let (defaults, listed) = if toml_path.exists() {
        let text = std::fs::read_to_string(&toml_path)
            .map_err(|e| format!("{}: {e}", toml_path.display()))?;
        parse(&text, &toml_path)?
    } else {
        (Settings::default(), Vec::new())
    };
    let entries = if listed.is_empty() {
        top_level_scenes(dir)?
            .into_iter()
            .map(|rel| SceneEntry {
                file: dir.join(&rel),
                name: golden_name(&rel),
                settings: defaults.clone(),
            })
            .collect()
    } else {
        listed
            .into_iter()
            .map(|(rel, name, s)| SceneEntry {
                file: dir.join(&rel),
                name: name.unwrap_or_else(|| golden_name(&rel)),
                settings: s,
            })
            .collect::<Vec<_>>()
    };
    if entries.is_empty() {
        return Err(format!(
            "{}: no scenes (no .pbrt file at its top level and no [[scene]] in golden.toml)",
            dir.display()
        ));
    }
    let mut names: Vec<&str> = entries.iter().map(|e| e.name.as_str()).collect();
    names.sort();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return Err(format!(
            "{}: two scenes have the golden name {:?} (give one a `name`)",
            toml_path.display(),
            w[0]
        ));
    }
    Ok(entries)
}

fn top_level_scenes(dir: &Path) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let rd = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for e in rd.flatten() {
        let p = e.path();
        if p.is_file() && p.extension().is_some_and(|x| x == "pbrt") {
            if let Some(n) = p.file_name().and_then(|n| n.to_str()) {
                out.push(n.to_string());
            }
        }
    }
    out.sort();
    Ok(out)
}

fn golden_name(rel: &str) -> String {
    rel.trim_end_matches(".pbrt").replace(['/', '\\'], "-")
}

type Listed = Vec<(String, Option<String>, Settings)>;

/// Parses golden.toml's text (`path` names it in errors).
pub fn parse(text: &str, path: &Path) -> Result<(Settings, Listed), String> {
    let doc = DeTable::parse(text).map_err(|e| format!("{}: {e}", path.display()))?;
    let at = |span: std::ops::Range<usize>, key: &str, msg: String| {
        let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
        let col = span.start
            - text[..span.start.min(text.len())]
                .rfind('\n')
                .map_or(0, |i| i + 1)
            + 1;
        format!("{}:{line}:{col}: key `{key}`: {msg}", path.display())
    };
    let mut defaults = Settings::default();
    let mut listed = Vec::new();
    for (k, v) in doc.get_ref().iter() {
        let key = k.get_ref().as_ref();
        if key == "scene" {
            let Some(arr) = v.get_ref().as_array() else {
                return Err(at(v.span(), "scene", "expected [[scene]] tables".into()));
            };
            for item in arr.iter() {
                let Some(t) = item.get_ref().as_table() else {
                    return Err(at(item.span(), "scene", "expected a table".into()));
                };
                listed.push((item.span(), t));
            }
        } else {
            set(&mut defaults, key, v).map_err(|(s, m)| at(s, key, m))?;
        }
    }
    let mut out = Vec::new();
    for (span, t) in listed {
        let mut s = defaults.clone();
        let (mut file, mut name) = (None, None);
        for (k, v) in t.iter() {
            let key = k.get_ref().as_ref();
            let key_path = format!("scene.{key}");
            match key {
                "file" | "name" => {
                    let Some(x) = v.get_ref().as_str().filter(|x| !x.is_empty()) else {
                        return Err(at(
                            v.span(),
                            &key_path,
                            "expected a non-empty string".into(),
                        ));
                    };
                    if key == "file" {
                        file = Some(x.to_string());
                    } else {
                        name = Some(x.to_string());
                    }
                }
                _ => set(&mut s, key, v).map_err(|(sp, m)| at(sp, &key_path, m))?,
            }
        }
        let Some(file) = file else {
            return Err(at(span, "scene.file", "missing: which scene file?".into()));
        };
        out.push((file, name, s));
    }
    Ok((defaults, out))
}

type KeyError = (std::ops::Range<usize>, String);

fn set(s: &mut Settings, key: &str, v: &Spanned<DeValue>) -> Result<(), KeyError> {
    let bad = |m: &str| (v.span(), m.to_string());
    match key {
        "spp" => s.spp = Some(positive_int(v.get_ref()).ok_or_else(|| bad("expected an integer ≥ 1"))?),
        "resolution" => {
            let r = v
                .get_ref()
                .as_array()
                .filter(|a| a.len() == 2)
                .and_then(|a| Some((positive_int(a[0].get_ref())?, positive_int(a[1].get_ref())?)));
            s.resolution = Some(r.ok_or_else(|| bad("expected [width, height], integers ≥ 1"))?);
        }
        "tolerance" | "mean_tolerance" => {
            let x = number(v.get_ref())
                .filter(|x| *x > 0.0 && x.is_finite())
                .ok_or_else(|| bad("expected a number > 0"))?;
            if key == "tolerance" {
                s.tolerance = x;
            } else {
                s.mean_tolerance = x;
            }
        }
        _ => {
            return Err((
                v.span(),
                "unknown key (known: spp, resolution, tolerance, mean_tolerance, and file, name in [[scene]])".into(),
            ))
        }
    }
    Ok(())
}

fn positive_int(v: &DeValue) -> Option<u32> {
    let i = v.as_integer()?;
    let n = i64::from_str_radix(i.as_str(), i.radix()).ok()?;
    (1..=(1 << 24)).contains(&n).then_some(n as u32)
}

fn number(v: &DeValue) -> Option<f64> {
    if let Some(f) = v.as_float() {
        return f.as_str().parse().ok();
    }
    let i = v.as_integer()?;
    i64::from_str_radix(i.as_str(), i.radix())
        .ok()
        .map(|n| n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_defaults_and_scenes() {
        let t = "spp = 8\ntolerance = 3\n[[scene]]\nfile = \"a.pbrt\"\nresolution = [32, 16]\n[[scene]]\nfile = \"sub/b.pbrt\"\nname = \"bee\"\nmean_tolerance = 4.5\n";
        let (d, l) = parse(t, Path::new("g.toml")).unwrap();
        assert_eq!(d.spp, Some(8));
        assert_eq!(l.len(), 2);
        assert_eq!(l[0].2.resolution, Some((32, 16)));
        assert_eq!(l[0].2.tolerance, 3.0);
        assert_eq!(l[1].1.as_deref(), Some("bee"));
        assert_eq!(l[1].2.mean_tolerance, 4.5);
        assert_eq!(golden_name("sub/b.pbrt"), "sub-b");
    }

    #[test]
    fn errors_are_located_with_the_key() {
        let e = parse(
            "spp = 8\n[[scene]]\nfile = \"a.pbrt\"\nspp = -3\n",
            Path::new("g.toml"),
        )
        .unwrap_err();
        assert!(e.starts_with("g.toml:4:7: key `scene.spp`"), "{e}");
        let e = parse("tolerence = 2\n", Path::new("g.toml")).unwrap_err();
        assert!(
            e.contains("g.toml:1:13: key `tolerence`: unknown key"),
            "{e}"
        );
        let e = parse("[[scene]]\nname = \"x\"\n", Path::new("g.toml")).unwrap_err();
        assert!(e.contains("key `scene.file`: missing"), "{e}");
        let e = parse("spp = [1,\n", Path::new("g.toml")).unwrap_err();
        assert!(e.contains("g.toml") && e.contains("line"), "{e}");
    }
}
