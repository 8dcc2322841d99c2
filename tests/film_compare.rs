//! The comparison metrics against the figures of scenes/references/README.md.

use pbrs::image::compare::{
    block_error, compare, false_colour_difference, mean_rgb, relative_mse, rmse,
};
use pbrs::image::io::read_pfm;
use pbrs::image::Image;
use std::path::PathBuf;

fn reference(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/references")
        .join(name)
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

/// (stem, relative MSE, block error, RMSE, mean RGB at 64 spp, mean RGB converged)
#[allow(clippy::type_complexity)]
const TABLE: [(&str, f64, f64, f64, [f64; 3], [f64; 3]); 5] = [
    (
        "cornell-path",
        0.00218,
        0.00436,
        0.00888,
        [0.19552, 0.12733, 0.03612],
        [0.19553, 0.12736, 0.03612],
    ),
    (
        "cornell-direct",
        0.00078,
        0.00037,
        0.00579,
        [0.13920, 0.09539, 0.02994],
        [0.13917, 0.09538, 0.02993],
    ),
    (
        "cornell-glass",
        0.04466,
        0.02651,
        0.03654,
        [0.22081, 0.13911, 0.04000],
        [0.22041, 0.13883, 0.03993],
    ),
    (
        "bitterli-cornell-box",
        0.00111,
        0.00431,
        0.00626,
        [0.19622, 0.12752, 0.03610],
        [0.19622, 0.12752, 0.03610],
    ),
    (
        "dezeming-cornell-dragon",
        0.00610,
        0.00869,
        0.02889,
        [0.32384, 0.23716, 0.25210],
        [0.32371, 0.23706, 0.25218],
    ),
];

#[test]
fn cornell_path_matches_readme_figures() {
    let a = read_pfm(&reference("cornell-path-128-64.pfm")).unwrap();
    let r = read_pfm(&reference("cornell-path-128-16384.pfm")).unwrap();
    assert_eq!((a.width, a.height), (128, 128));
    let (m, b, e) = (relative_mse(&a, &r), block_error(&a, &r), rmse(&a, &r));
    println!("cornell-path: relative MSE {m:.5}, block error {b:.5}, RMSE {e:.5}");
    // The README rounds to 3 significant digits.
    assert!(close(m, 0.00218, 0.005), "relative MSE {m}");
    assert!(close(b, 0.00436, 0.005), "block error {b}");
    assert!(close(e, 0.00888, 0.005), "RMSE {e}");
}

#[test]
fn all_references_match_readme_table() {
    for (stem, m, b, e, ma, mr) in TABLE {
        let a = read_pfm(&reference(&format!("{stem}-128-64.pfm"))).unwrap();
        let r = read_pfm(&reference(&format!("{stem}-128-16384.pfm"))).unwrap();
        let c = compare(&a, &r);
        println!(
            "{stem}: rel MSE {:.5} block {:.5} RMSE {:.5} mean {:.5?} / {:.5?}",
            c.relative_mse, c.block_error, c.rmse, c.mean_a, c.mean_r
        );
        assert!(
            close(c.relative_mse, m, 0.01),
            "{stem}: relative MSE {} vs {m}",
            c.relative_mse
        );
        assert!(
            close(c.block_error, b, 0.015),
            "{stem}: block error {} vs {b}",
            c.block_error
        );
        assert!(close(c.rmse, e, 0.01), "{stem}: RMSE {} vs {e}", c.rmse);
        for ch in 0..3 {
            assert!(
                (c.mean_a[ch] - ma[ch]).abs() <= 6e-6,
                "{stem}: mean {:?} vs {ma:?}",
                c.mean_a
            );
            assert!(
                (c.mean_r[ch] - mr[ch]).abs() <= 6e-6,
                "{stem}: mean {:?} vs {mr:?}",
                c.mean_r
            );
        }
    }
}

#[test]
fn metrics_on_small_images() {
    let r = Image {
        width: 2,
        height: 1,
        data: vec![1.0, 0.0, 0.5, 0.0, 0.0, 0.0],
    };
    let a = Image {
        width: 2,
        height: 1,
        data: vec![1.1, 0.0, 0.5, 0.0, 0.1, 0.0],
    };
    assert_eq!(relative_mse(&r, &r), 0.0);
    assert_eq!(block_error(&r, &r), 0.0);
    let expect = (0.01 / 1.01 + 0.01 / 0.01) / 6.0;
    assert!((relative_mse(&a, &r) - expect).abs() < 1e-6);
    assert!((rmse(&a, &r) - (0.02f64 / 6.0).sqrt()).abs() < 1e-7);
    // One block: means (0.55, 0.05, 0.25) vs (0.5, 0, 0.25).
    let be = ((0.05f64.powi(2) / 0.26 + 0.05f64.powi(2) / 0.01) / 3.0).sqrt();
    assert!(
        (block_error(&a, &r) - be).abs() < 1e-6,
        "{} vs {be}",
        block_error(&a, &r)
    );
    assert_eq!(mean_rgb(&r), [0.5, 0.0, 0.25]);
    let fc = false_colour_difference(&a, &r);
    assert_eq!((fc.width, fc.height), (2, 1));
    assert!(fc.data.iter().all(|v| (0.0..=1.0).contains(v)));
    assert_eq!(&false_colour_difference(&r, &r).data, &vec![0.0; 6]);
}
