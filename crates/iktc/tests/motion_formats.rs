//! The motion files of other pipelines (`iktc::batch::formats`) written for a synthetic G1 clip
//! whose motion is known in closed form, and read back as their consumers read them: the
//! pickle by a small pickle machine that runs the opcodes and the NumPy calls it names, the
//! NPZ by a zip and `.npy` reader written from their specifications, the CSV as
//! `numpy.loadtxt(delimiter=",")` does. Checked: keys, shapes, quaternion order against a known
//! rotation, joint order, rate, body positions against forward kinematics worked by hand from
//! the URDF, and body velocities against central differences of the positions written.

use std::collections::BTreeMap;
use std::f64::consts::FRAC_PI_2;

use iktc::batch::{body_links, MotionFormat, TrainingTrajectory};
use iktc::model::{g1, ModelOptions, Robot};

/// Output rate of the synthetic clip \[Hz\].
const RATE: f64 = 500.0;
/// Frames of the synthetic clip.
const FRAMES: usize = 40;
/// Forward speed of the base along world x \[m/s\].
const BASE_SPEED: f64 = 0.3;
/// Yaw rate of the base about world z \[rad/s\].
const YAW_RATE: f64 = 0.7;
/// Amplitude of every joint's sine \[rad\].
const AMPLITUDE: f64 = 0.2;
/// Angular frequency of every joint's sine \[rad/s\].
const OMEGA: f64 = 2.0;
/// Equality of values written and read back, or of two routes to one kinematic quantity
/// \[m\], \[rad\], \[–\]: round-off only.
const EXACT: f64 = 1e-12;
/// Round-off of `float32` values near 1 m \[m\]: 2⁻²⁴ relative, with room.
const F32_ROUNDING: f64 = 1e-6;
/// Central differences over 2/RATE s against the velocities written \[m/s\], \[rad/s\]: the
/// difference's truncation, h²/6 times the third derivative (≈ 1 m/s³ here), is ≈ 1e-6.
const CENTRAL_DIFFERENCE: f64 = 1e-4;

fn robot() -> Robot {
    g1(&ModelOptions::default()).unwrap()
}

fn yaw(t: f64) -> f64 {
    FRAC_PI_2 + YAW_RATE * t
}

/// The clip: the base moving along x at `BASE_SPEED` and turning about z from 90° at
/// `YAW_RATE`, joint i at `AMPLITUDE sin(OMEGA t + 0.1 i)`; rates are the exact derivatives.
fn clip(robot: &Robot) -> TrainingTrajectory {
    let joints: Vec<String> = robot.active_joints().map(|j| j.name.clone()).collect();
    let mut tr = TrainingTrajectory {
        fps: RATE,
        joint_names: joints.clone(),
        body_names: vec![],
        time: vec![],
        base_pos: vec![],
        base_quat_xyzw: vec![],
        base_lin_vel: vec![],
        base_ang_vel: vec![],
        joint_pos: vec![],
        joint_vel: vec![],
        body_pos: vec![],
    };
    for j in 0..FRAMES {
        let t = j as f64 / RATE;
        let y = yaw(t);
        tr.time.push(t);
        tr.base_pos.push([1.0 + BASE_SPEED * t, 2.0, 0.8]);
        tr.base_quat_xyzw
            .push([0.0, 0.0, (y / 2.0).sin(), (y / 2.0).cos()]);
        // The world velocity (BASE_SPEED, 0, 0) in the base's axes: Rz(yaw)ᵀ v.
        tr.base_lin_vel
            .push([BASE_SPEED * y.cos(), -BASE_SPEED * y.sin(), 0.0]);
        tr.base_ang_vel.push([0.0, 0.0, YAW_RATE]);
        let phase = |i: usize| OMEGA * t + 0.1 * i as f64;
        tr.joint_pos.push(
            (0..joints.len())
                .map(|i| AMPLITUDE * phase(i).sin())
                .collect(),
        );
        tr.joint_vel.push(
            (0..joints.len())
                .map(|i| AMPLITUDE * OMEGA * phase(i).cos())
                .collect(),
        );
        tr.body_pos.push(vec![]);
    }
    tr
}

/// The left hip's links by hand from the URDF: `left_hip_pitch_joint` at (0, 0.064452,
/// −0.1027) in the pelvis, axis y; `left_hip_roll_joint` at (0, 0.052, −0.030465) in the hip
/// pitch link. Returns (pitch link, roll link) positions in the pelvis frame at hip pitch `q`.
fn left_hip_by_hand(q: f64) -> ([f64; 3], [f64; 3]) {
    let pitch = [0.0, 0.064452, -0.1027];
    // Ry(q) (0, 0.052, −0.030465) = (−0.030465 sin q, 0.052, −0.030465 cos q).
    let roll = [
        pitch[0] - 0.030465 * q.sin(),
        pitch[1] + 0.052,
        pitch[2] - 0.030465 * q.cos(),
    ];
    (pitch, roll)
}

/// A point of the pelvis frame in the world at frame `j`: base + Rz(yaw) p.
fn to_world(j: usize, p: [f64; 3]) -> [f64; 3] {
    let t = j as f64 / RATE;
    let (s, c) = yaw(t).sin_cos();
    [
        1.0 + BASE_SPEED * t + c * p[0] - s * p[1],
        2.0 + s * p[0] + c * p[1],
        0.8 + p[2],
    ]
}

fn close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= tol,
            "{what}[{i}]: {x} vs {y} (tolerance {tol})"
        );
    }
}

// ---- a pickle machine: the opcodes of CPython's Lib/pickletools.py, NumPy calls by name ----

#[derive(Debug, Clone, PartialEq)]
enum Py {
    None,
    Int(i64),
    Float(f64),
    Str(String),
    Bytes(Vec<u8>),
    List(Vec<Py>),
    Tuple(Vec<Py>),
    Dict(Vec<(Py, Py)>),
    Global(String, String),
    /// A NumPy array: dtype string, shape, values.
    Array(String, Vec<usize>, Vec<f64>),
    Mark,
}

/// What calling `f` with `args` gives, for the callables a motion pickle may name.
fn call(f: &Py, args: Vec<Py>) -> Py {
    let Py::Global(m, n) = f else {
        panic!("call of {f:?}")
    };
    match (m.as_str(), n.as_str(), args.as_slice()) {
        ("builtins", "bytearray", [Py::Bytes(b)]) => Py::Bytes(b.clone()),
        ("numpy", "frombuffer", [Py::Bytes(b), Py::Str(dtype)]) => {
            let values: Vec<f64> = match dtype.as_str() {
                "<f8" => b
                    .chunks_exact(8)
                    .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                    .collect(),
                "<f4" => b
                    .chunks_exact(4)
                    .map(|c| f64::from(f32::from_le_bytes(c.try_into().unwrap())))
                    .collect(),
                other => panic!("dtype {other}"),
            };
            Py::Array(dtype.clone(), vec![values.len()], values)
        }
        ("numpy", "reshape", [Py::Array(d, _, v), Py::Tuple(shape)]) => {
            let shape: Vec<usize> = shape
                .iter()
                .map(|s| match s {
                    Py::Int(i) => usize::try_from(*i).unwrap(),
                    other => panic!("shape entry {other:?}"),
                })
                .collect();
            assert_eq!(shape.iter().product::<usize>(), v.len(), "reshape size");
            Py::Array(d.clone(), shape, v.clone())
        }
        _ => panic!("the pickle calls {m}.{n} with {args:?}, which a motion file has no need of"),
    }
}

fn unpickle(b: &[u8]) -> Py {
    let mut stack: Vec<Py> = Vec::new();
    let mut i = 0;
    let take = |i: &mut usize, n: usize| {
        let s = &b[*i..*i + n];
        *i += n;
        s
    };
    let since_mark = |stack: &mut Vec<Py>| {
        let m = stack.iter().rposition(|x| *x == Py::Mark).expect("MARK");
        let items = stack.split_off(m + 1);
        stack.pop();
        items
    };
    loop {
        let op = take(&mut i, 1)[0];
        match op {
            0x80 => assert!(take(&mut i, 1)[0] <= 5, "protocol"),
            b'}' => stack.push(Py::Dict(vec![])),
            b']' => stack.push(Py::List(vec![])),
            b'(' => stack.push(Py::Mark),
            b'N' => stack.push(Py::None),
            b'J' => {
                let v = i32::from_le_bytes(take(&mut i, 4).try_into().unwrap());
                stack.push(Py::Int(i64::from(v)));
            }
            b'K' => stack.push(Py::Int(i64::from(take(&mut i, 1)[0]))),
            b'G' => stack.push(Py::Float(f64::from_be_bytes(
                take(&mut i, 8).try_into().unwrap(),
            ))),
            0x8c => {
                let n = usize::from(take(&mut i, 1)[0]);
                stack.push(Py::Str(
                    String::from_utf8(take(&mut i, n).to_vec()).unwrap(),
                ));
            }
            b'X' => {
                let n = u32::from_le_bytes(take(&mut i, 4).try_into().unwrap()) as usize;
                stack.push(Py::Str(
                    String::from_utf8(take(&mut i, n).to_vec()).unwrap(),
                ));
            }
            b'B' => {
                let n = u32::from_le_bytes(take(&mut i, 4).try_into().unwrap()) as usize;
                stack.push(Py::Bytes(take(&mut i, n).to_vec()));
            }
            0x8e => {
                let n = u64::from_le_bytes(take(&mut i, 8).try_into().unwrap()) as usize;
                stack.push(Py::Bytes(take(&mut i, n).to_vec()));
            }
            b'c' => {
                let rest = &b[i..];
                let nl1 = rest.iter().position(|c| *c == b'\n').unwrap();
                let nl2 = nl1 + 1 + rest[nl1 + 1..].iter().position(|c| *c == b'\n').unwrap();
                let m = String::from_utf8(rest[..nl1].to_vec()).unwrap();
                let n = String::from_utf8(rest[nl1 + 1..nl2].to_vec()).unwrap();
                i += nl2 + 1;
                stack.push(Py::Global(m, n));
            }
            0x85..=0x87 => {
                let n = usize::from(op - 0x84);
                let items = stack.split_off(stack.len() - n);
                stack.push(Py::Tuple(items));
            }
            b't' => {
                let items = since_mark(&mut stack);
                stack.push(Py::Tuple(items));
            }
            b'R' => {
                let Some(Py::Tuple(args)) = stack.pop() else {
                    panic!("REDUCE without an argument tuple")
                };
                let f = stack.pop().unwrap();
                stack.push(call(&f, args));
            }
            b'e' => {
                let items = since_mark(&mut stack);
                match stack.last_mut() {
                    Some(Py::List(l)) => l.extend(items),
                    other => panic!("APPENDS onto {other:?}"),
                }
            }
            b'u' => {
                let items = since_mark(&mut stack);
                let Some(Py::Dict(d)) = stack.last_mut() else {
                    panic!("SETITEMS onto a non-dict")
                };
                let mut it = items.into_iter();
                while let (Some(k), Some(v)) = (it.next(), it.next()) {
                    d.push((k, v));
                }
            }
            b'.' => {
                assert_eq!(i, b.len(), "bytes after STOP");
                assert_eq!(stack.len(), 1);
                return stack.pop().unwrap();
            }
            other => panic!("opcode {other:#x} at {}", i - 1),
        }
    }
}

fn dict(p: Py) -> BTreeMap<String, Py> {
    let Py::Dict(items) = p else {
        panic!("not a dict: {p:?}")
    };
    items
        .into_iter()
        .map(|(k, v)| match k {
            Py::Str(k) => (k, v),
            other => panic!("key {other:?}"),
        })
        .collect()
}

fn array<'a>(d: &'a BTreeMap<String, Py>, key: &str) -> (&'a str, &'a [usize], &'a [f64]) {
    match &d[key] {
        Py::Array(dt, s, v) => (dt, s, v),
        other => panic!("{key}: {other:?}"),
    }
}

// ---- an .npz reader: zip local headers (stored members) and .npy v1.0 ----

#[derive(Debug)]
enum Npy {
    F64(Vec<usize>, Vec<f64>),
    Str(Vec<String>),
}

fn read_npz(b: &[u8]) -> BTreeMap<String, Npy> {
    let u16_at = |i: usize| usize::from(u16::from_le_bytes([b[i], b[i + 1]]));
    let u32_at = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap()) as usize;
    let mut out = BTreeMap::new();
    let mut at = 0;
    while u32_at(at) == 0x0403_4b50 {
        assert_eq!(u16_at(at + 8), 0, "stored");
        let size = u32_at(at + 18);
        let (nlen, elen) = (u16_at(at + 26), u16_at(at + 28));
        let name = std::str::from_utf8(&b[at + 30..at + 30 + nlen]).unwrap();
        let start = at + 30 + nlen + elen;
        let npy = &b[start..start + size];
        out.insert(name.trim_end_matches(".npy").to_string(), parse_npy(npy));
        at = start + size;
    }
    out
}

fn parse_npy(b: &[u8]) -> Npy {
    assert_eq!(&b[..8], b"\x93NUMPY\x01\x00");
    let hlen = usize::from(u16::from_le_bytes([b[8], b[9]]));
    let header = std::str::from_utf8(&b[10..10 + hlen]).unwrap();
    let after = |key: &str| &header[header.find(key).unwrap() + key.len()..];
    let descr = after("'descr': '").split('\'').next().unwrap();
    assert!(after("'fortran_order': ").starts_with("False"));
    let shape_text = after("'shape': (").split(')').next().unwrap();
    let shape: Vec<usize> = shape_text
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let data = &b[10 + hlen..];
    let n: usize = shape.iter().product();
    if descr == "<f8" {
        assert_eq!(data.len(), 8 * n);
        Npy::F64(
            shape,
            data.chunks(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect(),
        )
    } else {
        let width: usize = descr.strip_prefix("<U").unwrap().parse().unwrap();
        Npy::Str(
            data.chunks(4 * width)
                .map(|c| {
                    c.chunks(4)
                        .map(|u| u32::from_le_bytes(u.try_into().unwrap()))
                        .filter(|u| *u != 0)
                        .map(|u| char::from_u32(u).unwrap())
                        .collect()
                })
                .collect(),
        )
    }
}

fn floats<'a>(npz: &'a BTreeMap<String, Npy>, key: &str) -> (&'a [usize], &'a [f64]) {
    match &npz[key] {
        Npy::F64(s, v) => (s, v),
        other => panic!("{key}: {other:?}"),
    }
}

// ---- the tests ----

#[test]
fn format_names_parse_and_an_unknown_one_lists_the_valid_ones() {
    let f = MotionFormat::parse_list(&["gmr,lafan-csv", "mjlab", " gmr"]).unwrap();
    assert_eq!(
        f,
        [
            MotionFormat::Gmr,
            MotionFormat::LafanCsv,
            MotionFormat::Mjlab
        ]
    );
    let none: [&str; 0] = [];
    assert_eq!(
        MotionFormat::parse_list(&none).unwrap(),
        [MotionFormat::Csv, MotionFormat::Npz]
    );
    for bad in ["gmr,bvh", "", "gmr,"] {
        let e = MotionFormat::parse_list(&[bad]).unwrap_err().to_string();
        assert!(e.contains("output format"), "{e}");
        for name in ["csv", "npz", "gmr", "lafan-csv", "mjlab"] {
            assert!(e.contains(name), "{bad}: {e}");
        }
    }
    // File names are distinct.
    let mut names: Vec<&str> = MotionFormat::ALL.iter().map(|f| f.file_name()).collect();
    names.dedup();
    assert_eq!(names.len(), MotionFormat::ALL.len());
}

#[test]
fn g1_bodies_are_pelvis_then_the_link_of_each_joint_in_joint_order() {
    let r = robot();
    let bodies = body_links(&r);
    let joints: Vec<String> = r.active_joints().map(|j| j.name.clone()).collect();
    assert_eq!(joints.len(), 29);
    assert_eq!(bodies.len(), 30);
    assert_eq!(bodies[0], "pelvis");
    // The G1's URDF names the link a joint moves after the joint (`X_joint` moves `X_link`),
    // but for `waist_pitch_joint`, which moves `torso_link`.
    for (j, b) in joints.iter().zip(&bodies[1..]) {
        let expected = match j.as_str() {
            "waist_pitch_joint" => "torso_link".to_string(),
            _ => j.replace("_joint", "_link"),
        };
        assert_eq!(*b, expected);
    }
    // Unitree's order: left leg, right leg, waist, left arm, right arm.
    assert_eq!(joints[0], "left_hip_pitch_joint");
    assert_eq!(joints[6], "right_hip_pitch_joint");
    assert_eq!(joints[12], "waist_yaw_joint");
    assert_eq!(joints[15], "left_shoulder_pitch_joint");
    assert_eq!(joints[22], "right_shoulder_pitch_joint");
    // Links on fixed joints are merged, as MuJoCo does.
    for fixed in [
        "head_link",
        "logo_link",
        "imu_in_pelvis",
        "pelvis_contour_link",
    ] {
        assert!(!bodies.iter().any(|b| b == fixed), "{fixed}");
    }
}

#[test]
fn gmr_pickle_reads_back_with_gmr_keys_and_semantics() {
    let r = robot();
    let tr = clip(&r);
    let bytes = MotionFormat::Gmr.encode(&r, &tr).unwrap();
    let d = dict(unpickle(&bytes));
    let keys: Vec<&str> = d.keys().map(String::as_str).collect();
    assert_eq!(
        keys,
        [
            "dof_pos",
            "fps",
            "link_body_list",
            "local_body_pos",
            "root_pos",
            "root_rot"
        ]
    );
    assert_eq!(d["fps"], Py::Int(500));
    let bodies = body_links(&r);
    assert_eq!(
        d["link_body_list"],
        Py::List(bodies.iter().map(|b| Py::Str(b.clone())).collect())
    );
    let (dt, s, root_pos) = array(&d, "root_pos");
    assert_eq!((dt, s), ("<f8", &[FRAMES, 3][..]));
    close(root_pos, &tr.base_pos.concat(), 0.0, "root_pos");
    let (dt, s, root_rot) = array(&d, "root_rot");
    assert_eq!((dt, s), ("<f8", &[FRAMES, 4][..]));
    // Frame 0 is turned 90° about z: x, y, z, w = (0, 0, sin 45°, cos 45°).
    let h = std::f64::consts::FRAC_1_SQRT_2;
    close(&root_rot[..4], &[0.0, 0.0, h, h], EXACT, "root_rot[0]");
    let (dt, s, dof) = array(&d, "dof_pos");
    assert_eq!((dt, s), ("<f8", &[FRAMES, 29][..]));
    close(dof, &tr.joint_pos.concat(), 0.0, "dof_pos");
    let (dt, s, local) = array(&d, "local_body_pos");
    assert_eq!((dt, s), ("<f4", &[FRAMES, 30, 3][..]));
    let body = |j: usize, b: usize| &local[(j * 30 + b) * 3..(j * 30 + b) * 3 + 3];
    for j in [0, FRAMES / 2, FRAMES - 1] {
        // The root's own row is zero; the hip's links are where the URDF puts them.
        close(body(j, 0), &[0.0; 3], 0.0, "root row");
        let (pitch, roll) = left_hip_by_hand(tr.joint_pos[j][0]);
        close(body(j, 1), &pitch, F32_ROUNDING, "left_hip_pitch_link");
        close(body(j, 2), &roll, F32_ROUNDING, "left_hip_roll_link");
    }
}

#[test]
fn lafan_csv_is_base_xyz_quaternion_xyzw_then_joints_without_header() {
    let r = robot();
    let tr = clip(&r);
    let text = String::from_utf8(MotionFormat::LafanCsv.encode(&r, &tr).unwrap()).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), FRAMES, "one row per frame, no header");
    let h = std::f64::consts::FRAC_1_SQRT_2;
    close(
        &rows[0][3..7],
        &[0.0, 0.0, h, h],
        EXACT,
        "quaternion x y z w",
    );
    for (j, row) in rows.iter().enumerate() {
        assert_eq!(row.len(), 36);
        close(&row[..3], &tr.base_pos[j], 0.0, "base");
        close(&row[3..7], &tr.base_quat_xyzw[j], 0.0, "quaternion");
        close(&row[7..], &tr.joint_pos[j], 0.0, "joints");
    }
}

#[test]
fn mjlab_npz_reads_back_with_world_poses_wxyz_and_kinematic_velocities() {
    let r = robot();
    let tr = clip(&r);
    let npz = read_npz(&MotionFormat::Mjlab.encode(&r, &tr).unwrap());
    let (s, fps) = floats(&npz, "fps");
    assert_eq!((s, fps), (&[1][..], &[RATE][..]));
    let (s, q) = floats(&npz, "joint_pos");
    assert_eq!(s, [FRAMES, 29]);
    close(q, &tr.joint_pos.concat(), 0.0, "joint_pos");
    let (_, qd) = floats(&npz, "joint_vel");
    close(qd, &tr.joint_vel.concat(), 0.0, "joint_vel");
    let Npy::Str(names) = &npz["body_names"] else {
        panic!("body_names")
    };
    assert_eq!(*names, body_links(&r));
    let (s, pos) = floats(&npz, "body_pos_w");
    assert_eq!(s, [FRAMES, 30, 3]);
    let (s, quat) = floats(&npz, "body_quat_w");
    assert_eq!(s, [FRAMES, 30, 4]);
    let (s, lin) = floats(&npz, "body_lin_vel_w");
    assert_eq!(s, [FRAMES, 30, 3]);
    let (s, ang) = floats(&npz, "body_ang_vel_w");
    assert_eq!(s, [FRAMES, 30, 3]);
    let at3 = |v: &[f64], j: usize, b: usize| [0, 1, 2].map(|k| v[(j * 30 + b) * 3 + k]);
    let at4 = |j: usize, b: usize| [0, 1, 2, 3].map(|k| quat[(j * 30 + b) * 4 + k]);
    // Frame 0's pelvis is turned 90° about z: w, x, y, z = (cos 45°, 0, 0, sin 45°).
    let h = std::f64::consts::FRAC_1_SQRT_2;
    close(
        &at4(0, 0),
        &[h, 0.0, 0.0, h],
        EXACT,
        "pelvis quaternion w x y z",
    );
    for j in 0..FRAMES {
        close(&at3(pos, j, 0), &tr.base_pos[j], EXACT, "pelvis position");
        let (pitch, roll) = left_hip_by_hand(tr.joint_pos[j][0]);
        close(
            &at3(pos, j, 1),
            &to_world(j, pitch),
            EXACT,
            "left_hip_pitch_link",
        );
        close(
            &at3(pos, j, 2),
            &to_world(j, roll),
            EXACT,
            "left_hip_roll_link",
        );
        // left_hip_pitch_link: Rz(yaw) Ry(q) = (cz cy, −sz sy, cz sy, sz cy), either sign.
        let (sz, cz) = (yaw(j as f64 / RATE) / 2.0).sin_cos();
        let (sy, cy) = (tr.joint_pos[j][0] / 2.0).sin_cos();
        let hand = [cz * cy, -sz * sy, cz * sy, sz * cy];
        let got = at4(j, 1);
        let sign = if got[0] * hand[0] < 0.0 { -1.0 } else { 1.0 };
        close(
            &got.map(|x| sign * x),
            &hand,
            EXACT,
            "left_hip_pitch_link quaternion",
        );
    }
    // Pelvis velocity is the base's, in world axes.
    for j in 0..FRAMES {
        close(
            &at3(lin, j, 0),
            &[BASE_SPEED, 0.0, 0.0],
            EXACT,
            "pelvis velocity",
        );
        close(&at3(ang, j, 0), &[0.0, 0.0, YAW_RATE], EXACT, "pelvis rate");
    }
    // Every body's velocity against central differences of what the file says.
    let dt = 1.0 / RATE;
    for j in 1..FRAMES - 1 {
        for (b, name) in names.iter().enumerate() {
            let (p0, p1) = (at3(pos, j - 1, b), at3(pos, j + 1, b));
            let fd = [0, 1, 2].map(|k| (p1[k] - p0[k]) / (2.0 * dt));
            close(
                &at3(lin, j, b),
                &fd,
                CENTRAL_DIFFERENCE,
                &format!("{name} v"),
            );
            // ω from R(t+h) R(t−h)ᵀ: the quaternion q1 q0⁻¹ = (cos θ/2, sin θ/2 n).
            let (a, c) = (at4(j - 1, b), at4(j + 1, b));
            let a_inv = [a[0], -a[1], -a[2], -a[3]];
            let d = [
                c[0] * a_inv[0] - c[1] * a_inv[1] - c[2] * a_inv[2] - c[3] * a_inv[3],
                c[0] * a_inv[1] + c[1] * a_inv[0] + c[2] * a_inv[3] - c[3] * a_inv[2],
                c[0] * a_inv[2] - c[1] * a_inv[3] + c[2] * a_inv[0] + c[3] * a_inv[1],
                c[0] * a_inv[3] + c[1] * a_inv[2] - c[2] * a_inv[1] + c[3] * a_inv[0],
            ];
            let sign = if d[0] < 0.0 { -1.0 } else { 1.0 };
            let v = [d[1], d[2], d[3]].map(|x| sign * x);
            let sin_half = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let angle = 2.0 * sin_half.atan2(sign * d[0]);
            let scale = if sin_half > 0.0 {
                angle / sin_half
            } else {
                2.0
            };
            let fd = v.map(|x| x * scale / (2.0 * dt));
            close(
                &at3(ang, j, b),
                &fd,
                CENTRAL_DIFFERENCE,
                &format!("{name} ω"),
            );
        }
    }
}

#[test]
fn gmr_local_positions_are_the_mjlab_world_positions_in_the_root_frame() {
    let r = robot();
    let tr = clip(&r);
    let d = dict(unpickle(&MotionFormat::Gmr.encode(&r, &tr).unwrap()));
    let (_, _, local) = array(&d, "local_body_pos");
    let npz = read_npz(&MotionFormat::Mjlab.encode(&r, &tr).unwrap());
    let (_, world) = floats(&npz, "body_pos_w");
    for j in 0..FRAMES {
        for b in 0..30 {
            let l = &local[(j * 30 + b) * 3..(j * 30 + b) * 3 + 3];
            let w = to_world(j, [l[0], l[1], l[2]]);
            close(
                &w,
                &world[(j * 30 + b) * 3..(j * 30 + b) * 3 + 3],
                F32_ROUNDING,
                "base + R local",
            );
        }
    }
}

#[test]
fn a_clip_of_another_robot_is_refused_naming_the_joints() {
    let r = robot();
    let mut tr = clip(&r);
    tr.joint_names.swap(0, 1);
    for f in [MotionFormat::Gmr, MotionFormat::Mjlab] {
        let e = f.encode(&r, &tr).unwrap_err().to_string();
        assert!(e.contains("left_hip_pitch_joint"), "{e}");
    }
}
