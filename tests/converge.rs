//! `pbrs converge`: progressive renders give decreasing error, a CSV, a plot.

mod common;
use common::*;
use std::process::Command;

#[test]
fn converge_writes_csv_and_plot_with_falling_error() {
    let out = output_dir("converge");
    let _ = std::fs::remove_file(out.join("converge.csv"));
    let o = Command::new(env!("CARGO_BIN_EXE_pbrs"))
        .args([
            "converge",
            "scenes/converge/path-uniform.pbrt",
            "--reference",
            "scenes/references/cornell-path-128-16384.pfm",
        ])
        .args([
            "--spp-max",
            "16",
            "--compare",
            "scenes/converge/direct-one.pbrt=scenes/references/cornell-direct-128-16384.pfm",
        ])
        .arg("--out")
        .arg(&out)
        .current_dir(repo())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("converge.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    // Two configurations × spp 1, 2, 4, 8, 16.
    assert_eq!(rows.len(), 10);
    for config in ["path-uniform", "direct-one"] {
        let r: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == config).collect();
        let first: f64 = r[0][4].parse().unwrap();
        let last: f64 = r[4][4].parse().unwrap();
        let t0: f64 = r[0][2].parse().unwrap();
        let t4: f64 = r[4][2].parse().unwrap();
        assert!(
            last < first / 3.0,
            "{config}: relative MSE {first} -> {last}"
        );
        assert!(t4 > t0, "{config}: time must grow");
    }
    let svg = std::fs::read_to_string(out.join("converge.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("slope"));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("| path-uniform |") && table.contains("efficiency"));
}
