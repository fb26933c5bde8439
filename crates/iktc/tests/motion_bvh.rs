//! Tests of the BVH reader, writer and conversions: Euler convention, units, position channels,
//! unwrapping, round trips.

use iktc::motion::{
    builtin_clip, bvh_rotation, read_bvh, write_bvh, BvhChannel, BvhClip, BvhExportOptions,
    BvhReadOptions, BvhWriteOptions, Clip, JointKind, LengthUnit, RotationOrder, UpAxis,
};
use nalgebra::{Matrix3, Rotation3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn metres() -> BvhReadOptions {
    BvhReadOptions {
        length_unit: LengthUnit::Metres,
        up_axis: UpAxis::Y,
        ..Default::default()
    }
}

/// A two-joint chain with an end site; `order` is the root's rotation channel list.
fn chain(order: &str, frames: &[&str]) -> String {
    format!(
        "HIERARCHY
ROOT Hips
{{
\tOFFSET 0 0 0
\tCHANNELS 6 Xposition Yposition Zposition {order}
\tJOINT Chest
\t{{
\t\tOFFSET 0 1 0
\t\tCHANNELS 3 Xrotation Yrotation Zrotation
\t\tEnd Site
\t\t{{
\t\t\tOFFSET 0 1 0
\t\t}}
\t}}
}}
MOTION
Frames: {}
Frame Time: 0.5
{}
",
        frames.len(),
        frames.join("\n")
    )
}

fn positions(clip: &Clip, frame: usize) -> Vec<Vector3<f64>> {
    clip.world_positions(frame).unwrap()
}

fn close(a: Vector3<f64>, b: Vector3<f64>) -> bool {
    (a - b).norm() < 1e-12
}

/// Hand-computed: Rx(90°)·y = z, Rz(90°)·y = −x, Rz(90°)·z = z, Ry(90°)·z = x.
#[test]
fn euler_channels_compose_in_the_listed_order() {
    // ZXY with (90, 90, 0): R = Rz·Rx·Ry, R·y = Rz(Rx y) = Rz z = z.
    let c = read_bvh(
        &chain("Zrotation Xrotation Yrotation", &["0 0 0 90 90 0 0 0 0"]),
        "zxy",
        &metres(),
    )
    .unwrap()
    .to_clip()
    .unwrap();
    let p = positions(&c, 0);
    assert!(close(p[1], Vector3::new(0.0, 0.0, 1.0)), "{:?}", p[1]);
    assert!(close(p[2], Vector3::new(0.0, 0.0, 2.0)));
    // XYZ with (90, 0, 90): R·y = Rx(Rz y) = Rx(−x) = −x.
    let c = read_bvh(
        &chain("Xrotation Yrotation Zrotation", &["0 0 0 90 0 90 0 0 0"]),
        "xyz",
        &metres(),
    )
    .unwrap()
    .to_clip()
    .unwrap();
    assert!(close(positions(&c, 0)[1], Vector3::new(-1.0, 0.0, 0.0)));
    // YXZ with (90, 90, 0): R·y = Ry(Rx y) = Ry z = x.
    let c = read_bvh(
        &chain("Yrotation Xrotation Zrotation", &["0 0 0 90 90 0 0 0 0"]),
        "yxz",
        &metres(),
    )
    .unwrap()
    .to_clip()
    .unwrap();
    assert!(close(positions(&c, 0)[1], Vector3::new(1.0, 0.0, 0.0)));
    // The child's own rotation applies to its children only: Chest Xrotation 90 moves the end
    // site from +y to +z relative to the chest.
    let c = read_bvh(
        &chain("Zrotation Xrotation Yrotation", &["1 2 3 0 0 0 90 0 0"]),
        "child",
        &metres(),
    )
    .unwrap()
    .to_clip()
    .unwrap();
    let p = positions(&c, 0);
    assert!(close(p[0], Vector3::new(1.0, 2.0, 3.0)));
    assert!(close(p[1], Vector3::new(1.0, 3.0, 3.0)));
    assert!(close(p[2], Vector3::new(1.0, 3.0, 4.0)));
}

/// bvh_rotation against explicit rotation matrices for random angles and all orders.
#[test]
fn bvh_rotation_matches_matrix_products() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let rx = |a: f64| Matrix3::new(1.0, 0.0, 0.0, 0.0, a.cos(), -a.sin(), 0.0, a.sin(), a.cos());
    let ry = |a: f64| Matrix3::new(a.cos(), 0.0, a.sin(), 0.0, 1.0, 0.0, -a.sin(), 0.0, a.cos());
    let rz = |a: f64| Matrix3::new(a.cos(), -a.sin(), 0.0, a.sin(), a.cos(), 0.0, 0.0, 0.0, 1.0);
    for order in [
        RotationOrder::Xyz,
        RotationOrder::Xzy,
        RotationOrder::Yxz,
        RotationOrder::Yzx,
        RotationOrder::Zxy,
        RotationOrder::Zyx,
    ] {
        let ch = order.channels();
        let v: Vec<f64> = (0..3).map(|_| rng.random_range(-3.0..3.0)).collect();
        let m = |c: BvhChannel, a: f64| match c {
            BvhChannel::Xrotation => rx(a),
            BvhChannel::Yrotation => ry(a),
            _ => rz(a),
        };
        let expected = m(ch[0], v[0]) * m(ch[1], v[1]) * m(ch[2], v[2]);
        let got: Rotation3<f64> = bvh_rotation(&ch, &v).to_rotation_matrix();
        assert!((got.matrix() - expected).norm() < 1e-12, "{order:?}");
    }
}

#[test]
fn position_channels_on_a_non_root_joint() {
    let text = "HIERARCHY
ROOT root
{
  OFFSET 0 0 0
  CHANNELS 3 Zrotation Xposition Yposition
  JOINT arm
  {
    OFFSET 0 100 0
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 0 10
    }
  }
}
MOTION
Frames: 1
Frame Time: 0.01
90 10 20 50 0 0 0 0 0
";
    let bvh = read_bvh(text, "arm", &BvhReadOptions::default()).unwrap();
    let c = bvh.to_clip().unwrap();
    let p = positions(&c, 0);
    // Root at (0.1, 0.2, 0) m rotated by Rz(90°): the arm at root + Rz(90)·(0.5, 1.0, 0) m.
    assert!(close(p[0], Vector3::new(0.1, 0.2, 0.0)));
    assert!(
        close(p[1], Vector3::new(0.1 - 1.0, 0.2 + 0.5, 0.0)),
        "{:?}",
        p[1]
    );
    assert!(close(p[2], p[1] + Vector3::new(0.0, 0.0, 0.1)));
    assert!(close(
        c.frame(0).unwrap().translations[1],
        Vector3::new(0.5, 0.0, 0.0)
    ));
    // One rotation channel: a hinge about z.
    assert_eq!(c.skeleton().joints()[0].kind, JointKind::Root);
    assert_eq!(c.skeleton().joints()[1].kind, JointKind::Spherical);
    assert_eq!(c.skeleton().joints()[2].kind, JointKind::Fixed);
    assert_eq!(c.skeleton().joints()[2].name, "arm_end");
    // The writer keeps position channels on the arm, and reading back gives the same poses.
    let again = read_bvh(
        &write_bvh(
            &BvhClip::from_clip(&c, &BvhExportOptions::default()).unwrap(),
            &BvhWriteOptions::default(),
        )
        .unwrap(),
        "again",
        &BvhReadOptions::default(),
    )
    .unwrap()
    .to_clip()
    .unwrap();
    for (a, b) in positions(&again, 0).iter().zip(&p) {
        assert!((a - b).norm() < 1e-12);
    }
}

#[test]
fn length_units_scale_offsets_and_positions() {
    let text = chain(
        "Zrotation Xrotation Yrotation",
        &["10 20 30 0 0 0 0 0 0", "1 2 3 0 0 0 0 0 0"],
    );
    let m = read_bvh(&text, "m", &metres()).unwrap();
    let cm = read_bvh(&text, "cm", &BvhReadOptions::default()).unwrap();
    let inch = read_bvh(
        &text,
        "in",
        &BvhReadOptions {
            length_unit: LengthUnit::Inches,
            ..metres()
        },
    )
    .unwrap();
    let custom = read_bvh(
        &text,
        "c",
        &BvhReadOptions {
            length_unit: LengthUnit::Custom {
                metres_per_unit: 0.0254,
            },
            ..metres()
        },
    )
    .unwrap();
    assert_eq!(inch.values(), custom.values());
    assert_eq!(cm.joints()[1].offset, Vector3::new(0.0, 0.01, 0.0));
    assert_eq!(m.joints()[1].offset, Vector3::new(0.0, 1.0, 0.0));
    let pm = positions(&m.to_clip().unwrap(), 0);
    let pc = positions(&cm.to_clip().unwrap(), 0);
    for (a, b) in pm.iter().zip(&pc) {
        assert!((a * 0.01 - b).norm() < 1e-15);
    }
    // Rotations are not scaled.
    assert_eq!(
        m.track(0, BvhChannel::Zrotation),
        cm.track(0, BvhChannel::Zrotation)
    );
    assert!(read_bvh(
        &text,
        "bad",
        &BvhReadOptions {
            length_unit: LengthUnit::Custom {
                metres_per_unit: -1.0
            },
            ..metres()
        }
    )
    .is_err());
    assert!((m.duration() - 0.5).abs() < 1e-15);
}

/// Yrotation passing through ±180°: the stored track is unwrapped by multiples of 360°, the
/// rotations are those of the file's values.
#[test]
fn angle_tracks_are_unwrapped_through_180_degrees() {
    let file: [f64; 7] = [170.0, 179.0, -179.0, -170.0, 175.0, -185.0, 539.0];
    let unwrapped: [f64; 7] = [170.0, 179.0, 181.0, 190.0, 175.0, 175.0, 179.0];
    let frames: Vec<String> = file
        .iter()
        .map(|y| format!("0 0 0 0 0 {y} 0 0 0"))
        .collect();
    let frames: Vec<&str> = frames.iter().map(|s| s.as_str()).collect();
    let bvh = read_bvh(
        &chain("Zrotation Xrotation Yrotation", &frames),
        "wrap",
        &metres(),
    )
    .unwrap();
    let track = bvh.track(0, BvhChannel::Yrotation).unwrap();
    for (t, u) in track.iter().zip(&unwrapped) {
        assert!((t - u.to_radians()).abs() < 1e-12, "{track:?}");
    }
    let clip = bvh.to_clip().unwrap();
    for (f, y) in file.iter().enumerate() {
        let expected = bvh_rotation(&[BvhChannel::Yrotation], &[y.to_radians()]);
        assert!(clip.frame(f).unwrap().root_orientation.angle_to(&expected) < 1e-12);
    }
    assert!(bvh.track(1, BvhChannel::Xposition).is_none());
}

/// write → read gives back the clip: random values on a hierarchy with every channel order and
/// position channels on a non-root joint, shortest-float and fixed-decimal output, cm and m.
#[test]
fn bvh_round_trip() {
    let text = "HIERARCHY
ROOT a
{
\tOFFSET 1 2 3
\tCHANNELS 6 Zposition Xrotation Xposition Yrotation Yposition Zrotation
\tJOINT b
\t{
\t\tOFFSET 0 10 0
\t\tCHANNELS 3 Yrotation Xrotation Zrotation
\t\tJOINT c
\t\t{
\t\t\tOFFSET 0 10 0
\t\t\tCHANNELS 4 Xposition Zrotation Yposition Xrotation
\t\t\tEnd Site
\t\t\t{
\t\t\t\tOFFSET 0 5 0
\t\t\t}
\t\t}
\t}
\tJOINT d
\t{
\t\tOFFSET -3 0 0
\t\tCHANNELS 1 Zrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0 -5 0
\t\t}
\t}
}
MOTION
Frames: 30
Frame Time: 0.0083333
";
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let mut full = text.to_string();
    for _ in 0..30 {
        let row: Vec<String> = (0..14)
            .map(|_| format!("{}", rng.random_range(-400.0..400.0)))
            .collect();
        full.push_str(&row.join(" "));
        full.push('\n');
    }
    for unit in [LengthUnit::Centimetres, LengthUnit::Metres] {
        let read_opts = BvhReadOptions {
            length_unit: unit,
            up_axis: UpAxis::Y,
            ..Default::default()
        };
        let x = read_bvh(&full, "x", &read_opts).unwrap();
        let written = write_bvh(
            &x,
            &BvhWriteOptions {
                length_unit: unit,
                decimals: None,
            },
        )
        .unwrap();
        let y = read_bvh(&written, "x", &read_opts).unwrap();
        assert_eq!(x.joints().len(), y.joints().len());
        for (a, b) in x.joints().iter().zip(y.joints()) {
            assert_eq!(a.name, b.name);
            assert_eq!(a.parent, b.parent);
            assert_eq!(a.channels, b.channels);
            assert!((a.offset - b.offset).norm() <= 1e-15 * (1.0 + a.offset.norm()));
        }
        for (a, b) in x.values().iter().zip(y.values()) {
            assert!((a - b).abs() <= 1e-14 * (1.0 + a.abs()), "{a} {b}");
        }
        assert_eq!(x.frame_time(), y.frame_time());
        // Six decimals: equal to 1e-6 file units.
        let written = write_bvh(
            &x,
            &BvhWriteOptions {
                length_unit: unit,
                decimals: Some(6),
            },
        )
        .unwrap();
        let z = read_bvh(&written, "x", &read_opts).unwrap();
        for (a, b) in x.values().iter().zip(z.values()) {
            assert!(
                (a - b).abs() <= 1e-6_f64.to_radians().max(1e-6 * unit.metres_per_unit()) * 1.01
            );
        }
    }
}

/// A DeepMimic clip → BVH text → clip: same joint positions in every frame, for every rotation
/// order; hinges are written as one channel; Euler tracks are continuous.
#[test]
fn clip_round_trip_through_bvh() {
    for name in ["humanoid3d_walk", "humanoid3d_dance_b"] {
        let clip = builtin_clip(name).unwrap();
        for order in [RotationOrder::Zxy, RotationOrder::Xyz, RotationOrder::Yzx] {
            let opts = BvhExportOptions {
                rotation_order: order,
                ..BvhExportOptions::default()
            };
            let bvh = BvhClip::from_clip(&clip, &opts).unwrap();
            let knee = bvh.joint_index("right_knee").unwrap();
            assert_eq!(bvh.joints()[knee].channels, vec![BvhChannel::Zrotation]);
            let n = bvh.channel_count();
            for f in 1..bvh.frame_count() {
                let (a, b) = (bvh.frame(f - 1).unwrap(), bvh.frame(f).unwrap());
                for c in 0..n {
                    assert!(
                        (a[c] - b[c]).abs() < std::f64::consts::PI,
                        "{name} {order:?} frame {f} channel {c}"
                    );
                }
            }
            let text = write_bvh(&bvh, &BvhWriteOptions::default()).unwrap();
            let back = read_bvh(&text, name, &BvhReadOptions::default())
                .unwrap()
                .to_clip()
                .unwrap();
            assert_eq!(back.frame_count(), clip.frame_count());
            assert!((back.duration() - clip.duration()).abs() < 1e-6);
            for (a, b) in back
                .skeleton()
                .joints()
                .iter()
                .zip(clip.skeleton().joints())
            {
                if a.kind != JointKind::Fixed {
                    assert_eq!(a.name, b.name);
                }
            }
            for f in 0..clip.frame_count() {
                for (a, b) in positions(&back, f).iter().zip(&positions(&clip, f)) {
                    assert!((a - b).norm() < 1e-9, "{name} {order:?} frame {f}");
                }
            }
        }
    }
}

#[test]
fn irregular_frame_times_are_refused() {
    let text = "{\"Frames\": [[0.03,0,0.85,0,1,0,0,0,1,0,0,0,1,0,0,0,1,0,0,0,0,1,0,0,0,1,0,0,0,0,1,0,0,0,0,1,0,0,0,1,0,0,0,0],\n[0.05,0,0.85,0,1,0,0,0,1,0,0,0,1,0,0,0,1,0,0,0,0,1,0,0,0,1,0,0,0,0,1,0,0,0,0,1,0,0,0,1,0,0,0,0],\n[0.03,0,0.85,0,1,0,0,0,1,0,0,0,1,0,0,0,1,0,0,0,0,1,0,0,0,1,0,0,0,0,1,0,0,0,0,1,0,0,0,1,0,0,0,0]]}";
    let clip = iktc::motion::read_deepmimic(text, "irregular").unwrap();
    assert!(BvhClip::from_clip(&clip, &BvhExportOptions::default()).is_err());
    let loose = BvhExportOptions {
        frame_time_tolerance: 0.02,
        ..BvhExportOptions::default()
    };
    assert!((BvhClip::from_clip(&clip, &loose).unwrap().frame_time() - 0.04).abs() < 1e-15);
}
