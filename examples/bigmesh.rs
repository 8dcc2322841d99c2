//! Writes a big triangle mesh for load and build benchmarks: a displaced
//! grid of exactly N triangles as a binary little-endian PLY (float `x y z`,
//! faces as `uchar int` lists), and next to it a scene (same name, `.pbrt`)
//! that renders it at 64x64, 1 spp, with a camera looking down at it.
//! Deterministic: the same N gives the same bytes.
//!
//! cargo run --release --example bigmesh -- N /tmp/big.ply
//! target/release/pbrs --stats /tmp/big.pbrt
//! /usr/bin/time -v target/release/pbrs /tmp/big.pbrt   # peak memory
//! /work/pbrt-v3/build/pbrt --nthreads 2 /tmp/big.pbrt  # side by side

use std::io::{BufWriter, Write};
use std::path::PathBuf;

fn main() -> std::io::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let (Some(n), Some(out)) = (args.get(1).and_then(|s| s.parse::<u64>().ok()), args.get(2))
    else {
        eprintln!("usage: bigmesh N out.ply (N triangles; writes out.ply and out.pbrt)");
        std::process::exit(2);
    };
    let n = n.max(2);
    // A grid of `cols` x `rows` cells, two triangles per cell, filled row
    // by row until N triangles are written (the last row may be partial).
    let cols = ((n as f64 / 2.0).sqrt().ceil() as u64).max(1);
    let rows = n.div_ceil(2 * cols);
    let nv = (cols + 1) * (rows + 1);
    let ply = PathBuf::from(out);
    let mut w = BufWriter::with_capacity(1 << 20, std::fs::File::create(&ply)?);
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment pbrs examples/bigmesh: {n} triangles\n\
         element vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {n}\nproperty list uchar int vertex_indices\nend_header\n"
    )?;
    // The grid spans [-1, 1] in x and a proportional extent in y; z is a
    // sum of waves, fine enough that neighbouring triangles differ.
    let scale = 2.0 / cols as f64;
    for j in 0..=rows {
        for i in 0..=cols {
            let x = -1.0 + i as f64 * scale;
            let y = -1.0 + j as f64 * scale;
            let z = 0.08 * (7.0 * x).sin() * (5.0 * y).cos()
                + 0.02 * (31.0 * x + 17.0 * y).sin()
                + 0.005 * (173.0 * x).cos() * (211.0 * y).sin();
            for c in [x as f32, y as f32, z as f32] {
                w.write_all(&c.to_le_bytes())?;
            }
        }
    }
    let mut written = 0u64;
    'grid: for j in 0..rows {
        for i in 0..cols {
            let a = j * (cols + 1) + i;
            let (b, c, d) = (a + 1, a + cols + 2, a + cols + 1);
            for tri in [[a, b, c], [a, c, d]] {
                if written == n {
                    break 'grid;
                }
                w.write_all(&[3u8])?;
                for v in tri {
                    w.write_all(&(v as i32).to_le_bytes())?;
                }
                written += 1;
            }
        }
    }
    w.flush()?;
    let y_top = -1.0 + rows as f64 * scale;
    let cy = (y_top - 1.0) / 2.0;
    let scene = ply.with_extension("pbrt");
    let name = ply.file_name().expect("a file name").to_string_lossy();
    let film = scene
        .with_extension("exr")
        .file_name()
        .expect("a file name")
        .to_string_lossy()
        .into_owned();
    std::fs::write(
        &scene,
        format!(
            "# {n} triangles in {name} (pbrs examples/bigmesh)\n\
             LookAt 0 {ey:.4} 2.2  0 {cy:.4} 0  0 0 1\n\
             Camera \"perspective\" \"float fov\" 45\n\
             Film \"image\" \"integer xresolution\" 64 \"integer yresolution\" 64 \"string filename\" \"{film}\"\n\
             Sampler \"halton\" \"integer pixelsamples\" 1\n\
             Integrator \"directlighting\"\n\
             WorldBegin\n\
             LightSource \"distant\" \"point from\" [1 -1 3] \"point to\" [0 0 0] \"rgb L\" [3 3 3]\n\
             Material \"matte\" \"rgb Kd\" [0.6 0.5 0.4]\n\
             Shape \"plymesh\" \"string filename\" \"{name}\"\n\
             WorldEnd\n",
            ey = cy - 1.6,
        ),
    )?;
    eprintln!(
        "{}: {n} triangles, {nv} vertices; {}",
        ply.display(),
        scene.display()
    );
    Ok(())
}
