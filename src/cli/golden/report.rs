//! `pbrs test`'s output: a line per scene, the summary table, JUnit XML and
//! the HTML report.

use super::{Outcome, SceneResult};
use crate::image::compare::false_colour_difference_scaled;
use crate::image::io::{write_atomic, write_image};
use crate::image::verdict::Verdict;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// 2 if a scene had an error, else 1 if one failed, else 0.
pub fn status(results: &[SceneResult]) -> i32 {
    results
        .iter()
        .map(|r| match r.outcome {
            Outcome::Error(_) => 2,
            Outcome::Failed(_) => 1,
            _ => 0,
        })
        .max()
        .unwrap_or(0)
}

fn figures(r: &SceneResult, v: &Verdict) -> String {
    let [m, b, s] = r.ratios().unwrap_or_default();
    let c = &v.comparison;
    format!(
        "relative MSE {:.3e} = {m:.2}× noise (max {:.2}), block error {:.3e} = {b:.2}× noise (max {:.2}), mean difference {:.3e} = {s:.2} σ (max {:.2}), non-finite pixels {}",
        c.relative_mse,
        r.entry.settings.tolerance,
        c.block_error,
        r.entry.settings.tolerance,
        v.mean_difference,
        r.entry.settings.mean_tolerance,
        v.nonfinite
    )
}

/// The line printed as a scene finishes.
pub fn print_line(r: &SceneResult, quiet: bool) {
    match &r.outcome {
        Outcome::Passed(_) | Outcome::Updated if quiet => {}
        Outcome::Passed(v) => eprintln!(
            "ok    {} ({:.1} s): {}",
            r.entry.name,
            r.seconds,
            figures(r, v)
        ),
        Outcome::Updated => eprintln!("wrote golden/{}.exr ({:.1} s)", r.entry.name, r.seconds),
        Outcome::Failed(v) => eprintln!(
            "FAIL  {} ({:.1} s): {}; {}",
            r.entry.name,
            r.seconds,
            v.failures().join(", "),
            figures(r, v)
        ),
        Outcome::Error(e) => eprintln!("error {}: {e}", r.entry.name),
    }
}

/// The summary table (standard output) and a closing line.
pub fn print_table(results: &[SceneResult], seconds: f64, quiet: bool) {
    let width = results
        .iter()
        .map(|r| r.entry.name.len())
        .max()
        .unwrap_or(5)
        .max(5);
    if !quiet {
        println!(
            "{:width$}  {:7}  {:>12}  {:>12}  {:>9}  {:>10}  {:>7}",
            "scene", "result", "rel.MSE×noise", "block×noise", "mean σ", "non-finite", "time s"
        );
    }
    let (mut pass, mut fail, mut err, mut upd) = (0, 0, 0, 0);
    for r in results {
        let (word, cols) = match &r.outcome {
            Outcome::Passed(v) | Outcome::Failed(v) => {
                let [m, b, s] = r.ratios().unwrap_or_default();
                let word = if v.passed() { "pass" } else { "FAIL" };
                (
                    word,
                    format!("{m:>13.2}  {b:>12.2}  {s:>9.2}  {:>10}", v.nonfinite),
                )
            }
            Outcome::Updated => (
                "updated",
                format!("{:>13}  {:>12}  {:>9}  {:>10}", "", "", "", ""),
            ),
            Outcome::Error(_) => (
                "ERROR",
                format!("{:>13}  {:>12}  {:>9}  {:>10}", "", "", "", ""),
            ),
        };
        match word {
            "pass" => pass += 1,
            "FAIL" => fail += 1,
            "ERROR" => err += 1,
            _ => upd += 1,
        }
        if !quiet || word == "FAIL" || word == "ERROR" {
            println!(
                "{:width$}  {word:7}  {cols}  {:>7.1}",
                r.entry.name, r.seconds
            );
        }
    }
    println!(
        "{} scenes: {pass} passed, {fail} failed, {err} errors{} ({seconds:.1} s)",
        results.len(),
        if upd > 0 {
            format!(", {upd} goldens written")
        } else {
            String::new()
        }
    );
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// JUnit XML: one test case per scene, the figures in the failure message.
pub fn write_junit(path: &Path, dir: &Path, results: &[SceneResult]) -> Result<(), String> {
    let count = |f: fn(&Outcome) -> bool| results.iter().filter(|r| f(&r.outcome)).count();
    let failures = count(|o| matches!(o, Outcome::Failed(_)));
    let errors = count(|o| matches!(o, Outcome::Error(_)));
    let total: f64 = results.iter().map(|r| r.seconds).sum();
    let suite = xml(&format!("pbrs test {}", dir.display()));
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        s,
        "<testsuites name=\"{suite}\" tests=\"{}\" failures=\"{failures}\" errors=\"{errors}\" time=\"{total:.3}\">",
        results.len()
    );
    let _ = writeln!(
        s,
        "  <testsuite name=\"{suite}\" tests=\"{}\" failures=\"{failures}\" errors=\"{errors}\" time=\"{total:.3}\">",
        results.len()
    );
    for r in results {
        let name = xml(&r.entry.name);
        let file = xml(&r.entry.file.display().to_string());
        let _ = write!(
            s,
            "    <testcase name=\"{name}\" classname=\"pbrs.golden\" file=\"{file}\" time=\"{:.3}\"",
            r.seconds
        );
        match &r.outcome {
            Outcome::Failed(v) => {
                let msg = xml(&format!("{}: {}", v.failures().join(", "), figures(r, v)));
                let _ = writeln!(s, ">\n      <failure message=\"{msg}\" type=\"regression\">{msg}</failure>\n    </testcase>");
            }
            Outcome::Error(e) => {
                let msg = xml(e);
                let _ = writeln!(s, ">\n      <error message=\"{msg}\" type=\"bad input\">{msg}</error>\n    </testcase>");
            }
            Outcome::Passed(v) => {
                let msg = xml(&figures(r, v));
                let _ = writeln!(
                    s,
                    ">\n      <system-out>{msg}</system-out>\n    </testcase>"
                );
            }
            Outcome::Updated => {
                let _ = writeln!(
                    s,
                    ">\n      <system-out>golden written</system-out>\n    </testcase>"
                );
            }
        }
    }
    s.push_str("  </testsuite>\n</testsuites>\n");
    write_atomic(path, s.as_bytes()).map_err(|e| e.replace("cannot write image", "cannot write"))
}

/// The HTML report: a table of every scene and, for each failing one, the
/// golden, the render and the false-colour difference side by side.
pub fn write_html(out: &Path, dir: &Path, results: &[SceneResult]) -> Result<PathBuf, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut s = String::new();
    let title = xml(&format!("pbrs test {}", dir.display()));
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{title}</title><style>\
         body{{font-family:sans-serif}} td,th{{padding:2px 8px;text-align:right}} td:first-child{{text-align:left}}\
         .FAIL,.ERROR{{color:#b00;font-weight:bold}} img{{image-rendering:pixelated;width:256px;margin:4px}}\
         figure{{display:inline-block;margin:0}}</style></head><body>\n<h1>{title}</h1>\n<table>\n\
         <tr><th>scene</th><th>result</th><th>rel. MSE × noise</th><th>block × noise</th><th>mean σ</th><th>non-finite</th><th>time s</th></tr>\n"
    );
    for r in results {
        let name = xml(&r.entry.name);
        let (word, cols) = match &r.outcome {
            Outcome::Passed(v) | Outcome::Failed(v) => {
                let [m, b, sd] = r.ratios().unwrap_or_default();
                let w = if v.passed() { "pass" } else { "FAIL" };
                (
                    w,
                    format!(
                        "<td>{m:.2}</td><td>{b:.2}</td><td>{sd:.2}</td><td>{}</td>",
                        v.nonfinite
                    ),
                )
            }
            Outcome::Updated => (
                "updated",
                "<td></td><td></td><td></td><td></td>".to_string(),
            ),
            Outcome::Error(_) => ("ERROR", "<td></td><td></td><td></td><td></td>".to_string()),
        };
        let _ = writeln!(
            s,
            "<tr><td><a href=\"#{name}\">{name}</a></td><td class=\"{word}\">{word}</td>{cols}<td>{:.1}</td></tr>",
            r.seconds
        );
    }
    s.push_str("</table>\n");
    for r in results {
        let name = xml(&r.entry.name);
        match (&r.outcome, &r.images) {
            (Outcome::Failed(v), Some((img, golden))) => {
                // White at 3× the per-pixel noise expected between a render
                // and the golden: noise stays dark blue, changes stand out.
                let white = r.unit.map_or(0.5, |u| 3.0 * u.max_relative_mse.sqrt()) as f32;
                let files = [
                    ("golden", golden.clone()),
                    ("render", img.clone()),
                    (
                        "difference",
                        false_colour_difference_scaled(img, golden, white),
                    ),
                ];
                for (kind, im) in &files {
                    write_image(&out.join(format!("{}-{kind}.png", r.entry.name)), im)?;
                }
                let _ = writeln!(
                    s,
                    "<h2 id=\"{name}\">{name}: FAIL</h2>\n<p>{}</p>\n<p>{}</p>",
                    xml(&v.failures().join(", ")),
                    xml(&figures(r, v))
                );
                for (kind, _) in &files {
                    let f = xml(&format!("{}-{kind}.png", r.entry.name));
                    let _ = writeln!(s, "<figure><img src=\"{f}\" alt=\"{kind}\"><figcaption>{kind}</figcaption></figure>");
                }
                let _ = writeln!(s, "<p>difference: per-pixel relative error, black 0, blue, green, yellow, red, white ≥ {white:.3} (3× the expected noise)</p>");
            }
            (Outcome::Error(e), _) => {
                let _ = writeln!(
                    s,
                    "<h2 id=\"{name}\">{name}: ERROR</h2>\n<pre>{}</pre>",
                    xml(e)
                );
            }
            _ => {}
        }
    }
    s.push_str("</body></html>\n");
    let index = out.join("index.html");
    write_atomic(&index, s.as_bytes())
        .map_err(|e| e.replace("cannot write image", "cannot write"))?;
    Ok(index)
}
