//! A robot read from a URDF on disk gets the STL meshes next to it in its viewer; a missing
//! mesh file is a warning naming it, and a robot with no usable mesh keeps the stick figure.

use std::path::Path;
use std::process::Command;

/// A binary STL of a closed box `size` \[m\] (12 triangles, outward counter-clockwise).
fn box_stl(size: [f32; 3]) -> Vec<u8> {
    let c = |i: usize| -> [f32; 3] {
        std::array::from_fn(|k| {
            if i >> k & 1 == 1 {
                size[k] / 2.0
            } else {
                -size[k] / 2.0
            }
        })
    };
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut b = vec![0u8; 80];
    b.extend(12u32.to_le_bytes());
    for q in quads {
        for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            for x in [0f32; 3].into_iter().chain(t.iter().flat_map(|&i| c(i))) {
                b.extend(x.to_le_bytes());
            }
            b.extend([0u8, 0]);
        }
    }
    b
}

/// Writes the G1 URDF and profile into `dir` (the profile naming the URDF next to it).
fn g1_on_disk(dir: &Path) {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../iktc/data");
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::copy(
        data.join("robots/g1/g1_29dof_rev_1_0.urdf"),
        dir.join("g1.urdf"),
    )
    .unwrap();
    let profile = std::fs::read_to_string(data.join("profiles/g1.toml")).unwrap();
    let profile: String = profile
        .lines()
        .map(|l| {
            if l.starts_with("urdf = ") {
                "urdf = \"g1.urdf\"".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(dir.join("g1.toml"), profile).unwrap();
}

fn imitate(profile: &Path, out: &Path) -> (String, String) {
    let run = Command::new(env!("CARGO_BIN_EXE_iktc"))
        .args(["imitate", "--robot"])
        .arg(profile)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(run.status.success(), "iktc imitate failed: {stderr}");
    (
        std::fs::read_to_string(out.join("viewer.html")).unwrap(),
        stderr,
    )
}

#[test]
fn meshes_next_to_a_urdf_are_drawn_and_missing_ones_warned() {
    let dir = std::env::temp_dir().join(format!("iktc_viewer_meshes_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    g1_on_disk(&dir);

    // No mesh file at all: the first missing ones named, the rest counted (35 meshes in the
    // G1 URDF), and the stick figure.
    let (html, stderr) = imitate(&dir.join("g1.toml"), &dir.join("none"));
    assert!(
        !html.contains("\"meshes\""),
        "meshes in a page without mesh files"
    );
    assert!(
        stderr.contains("meshes/pelvis.STL") && stderr.contains("cannot read"),
        "no warning naming the pelvis's mesh: {stderr}"
    );
    assert!(
        stderr.contains("32 more meshes left out (35 in all)") && stderr.contains("stick figure"),
        "{stderr}"
    );
    assert_eq!(stderr.matches("warning: viewer:").count(), 4, "{stderr}");

    // The pelvis's mesh only: a 12-triangle box 0.1–0.3 m wide, far larger than the 12 mm
    // decimation cell, so kept whole.
    std::fs::write(dir.join("meshes/pelvis.STL"), box_stl([0.2, 0.3, 0.1])).unwrap();
    let (html, stderr) = imitate(&dir.join("g1.toml"), &dir.join("pelvis"));
    assert!(html.contains("\"meshes\""), "no meshes in the page");
    assert!(
        html.contains("\"triangles\":12"),
        "not the box's 12 triangles"
    );
    assert!(!stderr.contains("meshes/pelvis.STL"), "{stderr}");
    assert!(
        stderr.contains("31 more meshes left out (34 in all)")
            && stderr.contains("the links whose meshes were read"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
