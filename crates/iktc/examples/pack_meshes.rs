//! Packs the visual meshes of a URDF for the viewer (decimated on `iktc::mesh::VIEWER_CELL`,
//! 16-bit quantized): `cargo run -p iktc --release --example pack_meshes -- ROBOT.urdf OUT.bin
//! [CELL]`, CELL the clustering cube side \[m\] (default `VIEWER_CELL`).
//! Made the built-in G1's `data/robots/g1/meshes.bin` from Unitree's description folder.

use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (urdf, out, cell) = match args.as_slice() {
        [u, o] => (u, o, iktc::mesh::VIEWER_CELL),
        [u, o, c] => (u, o, c.parse().map_err(|e| format!("CELL `{c}`: {e}"))?),
        _ => return Err("usage: pack_meshes ROBOT.urdf OUT.bin [CELL]".into()),
    };
    let text = std::fs::read_to_string(urdf).map_err(|e| format!("reading {urdf}: {e}"))?;
    let dir = Path::new(urdf).parent().unwrap_or(Path::new("."));
    let m = iktc::mesh::urdf::meshes_from_urdf(&text, dir, cell)?;
    for w in &m.warnings {
        eprintln!("warning: {w}");
    }
    let bytes = iktc::mesh::pack(&m.set);
    std::fs::write(out, &bytes).map_err(|e| format!("writing {out}: {e}"))?;
    println!(
        "{} meshes, {} triangles, {} bytes written to {out}",
        m.set.meshes.len(),
        m.set.triangle_count(),
        bytes.len()
    );
    Ok(())
}
