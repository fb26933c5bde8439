//! Synthetic SMPL-family body models and AMASS archives written in the real files' layout
//! (`.npz` zips of `.npy` arrays, written with the `npyz` and `zip` crates), small enough to
//! compute their joints by hand.
//!
//! The model of J joints has V = 2J vertices: vertices `2j` and `2j + 1` sit at `P_j ± d_j`
//! and the joint regressor averages them, so the template's joint `j` is `P_j`. Shape
//! component 0 scales heights (`S[v, y, 0] = 0.1 · P_j.y` for both vertices of joint `j`),
//! component 1 scales widths (`S[v, x, 1] = 0.05 · P_j.x`), the others move the two vertices
//! of a joint in opposite directions and so leave the joints in place. Hence
//! `J_j(β) = (P_j.x (1 + 0.05 β₁), P_j.y (1 + 0.1 β₀), P_j.z)` [m].
//!
//! `P_j` is a standing adult in the body models' template frame: Y up, facing +Z, its left
//! along +X, feet on y = 0.
#![allow(dead_code)]

use std::f64::consts::FRAC_PI_2;
use std::io::{Cursor, Write};

use nalgebra::{UnitQuaternion, Vector3};
use npyz::WriterBuilder;

/// Height scale of shape component 0 [m per m of height per unit β₀].
pub const HEIGHT_SCALE: f64 = 0.1;

/// Width scale of shape component 1 [m per m of width per unit β₁].
pub const WIDTH_SCALE: f64 = 0.05;

/// SMPL's first 22 joints [m]: template positions (Y up, facing +Z, left along +X).
const BODY: [[f64; 3]; 22] = [
    [0.0, 0.93, 0.0],     // pelvis
    [0.08, 0.85, 0.0],    // left_hip
    [-0.08, 0.85, 0.0],   // right_hip
    [0.0, 1.03, -0.01],   // spine1
    [0.09, 0.48, 0.01],   // left_knee
    [-0.09, 0.48, 0.01],  // right_knee
    [0.0, 1.16, -0.01],   // spine2
    [0.09, 0.08, -0.03],  // left_ankle
    [-0.09, 0.08, -0.03], // right_ankle
    [0.0, 1.22, 0.0],     // spine3
    [0.1, 0.02, 0.11],    // left_foot
    [-0.1, 0.02, 0.11],   // right_foot
    [0.0, 1.44, -0.01],   // neck
    [0.07, 1.36, 0.0],    // left_collar
    [-0.07, 1.36, 0.0],   // right_collar
    [0.0, 1.53, 0.02],    // head
    [0.17, 1.38, -0.01],  // left_shoulder
    [-0.17, 1.38, -0.01], // right_shoulder
    [0.43, 1.38, -0.02],  // left_elbow
    [-0.43, 1.38, -0.02], // right_elbow
    [0.68, 1.38, -0.01],  // left_wrist
    [-0.68, 1.38, -0.01], // right_wrist
];

/// SMPL's parents of the first 22 joints (`-1` for the root).
const BODY_PARENTS: [i64; 22] = [
    -1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19,
];

/// The two layouts: SMPL-H (52 joints) and SMPL-X (55 joints).
pub const SMPLH: usize = 52;
/// See [`SMPLH`].
pub const SMPLX: usize = 55;

/// Index of the left wrist, right wrist, head (parents of the hands and of SMPL-X's face).
const LEFT_WRIST: usize = 20;
const RIGHT_WRIST: usize = 21;
const HEAD: usize = 15;

/// Template joint positions `P_j` [m] and parents of a model of `joints` (52 or 55) joints.
pub fn skeleton(joints: usize) -> (Vec<Vector3<f64>>, Vec<i64>) {
    let mut p: Vec<Vector3<f64>> = BODY.iter().map(|b| Vector3::from(*b)).collect();
    let mut parents = BODY_PARENTS.to_vec();
    if joints == SMPLX {
        for (x, parent_at) in [(0.0, 0.0), (0.03, 0.05), (-0.03, 0.05)] {
            p.push(Vector3::new(x, p[HEAD].y + parent_at, 0.08));
            parents.push(HEAD as i64);
        }
    }
    for (wrist, sign) in [(LEFT_WRIST, 1.0), (RIGHT_WRIST, -1.0)] {
        // Five fingers of three joints each, along the arm, spread along z.
        for finger in 0..5 {
            for k in 0..3 {
                let along = 0.06 + 0.025 * k as f64;
                let spread = 0.02 * (finger as f64 - 2.0);
                p.push(p[wrist] + Vector3::new(sign * along, 0.0, spread));
                parents.push(if k == 0 { wrist } else { p.len() - 2 } as i64);
            }
        }
    }
    assert_eq!(p.len(), joints);
    (p, parents)
}

/// The hand-computed rest joints `J(β)` of the model (see the module documentation) [m].
pub fn expected_joints(joints: usize, betas: &[f64]) -> Vec<Vector3<f64>> {
    let b = |i: usize| betas.get(i).copied().unwrap_or(0.0);
    skeleton(joints)
        .0
        .iter()
        .map(|p| {
            Vector3::new(
                p.x * (1.0 + WIDTH_SCALE * b(1)),
                p.y * (1.0 + HEIGHT_SCALE * b(0)),
                p.z,
            )
        })
        .collect()
}

/// One `.npy` member: an array of `shape` and C-order `data`, as `f32` or `f64`.
pub fn npy_floats(shape: &[usize], data: &[f64], float32: bool) -> Vec<u8> {
    let shape: Vec<u64> = shape.iter().map(|d| *d as u64).collect();
    let mut buf = Vec::new();
    if float32 {
        let mut w = npyz::WriteOptions::<f32>::new()
            .default_dtype()
            .shape(&shape)
            .writer(&mut buf)
            .begin_nd()
            .unwrap();
        w.extend(data.iter().map(|x| *x as f32)).unwrap();
        w.finish().unwrap();
    } else {
        let mut w = npyz::WriteOptions::<f64>::new()
            .default_dtype()
            .shape(&shape)
            .writer(&mut buf)
            .begin_nd()
            .unwrap();
        w.extend(data.iter().copied()).unwrap();
        w.finish().unwrap();
    }
    buf
}

/// One `.npy` member of unsigned 32-bit integers.
pub fn npy_u32(shape: &[usize], data: &[u32]) -> Vec<u8> {
    let shape: Vec<u64> = shape.iter().map(|d| *d as u64).collect();
    let mut buf = Vec::new();
    let mut w = npyz::WriteOptions::<u32>::new()
        .default_dtype()
        .shape(&shape)
        .writer(&mut buf)
        .begin_nd()
        .unwrap();
    w.extend(data.iter().copied()).unwrap();
    w.finish().unwrap();
    buf
}

/// One `.npy` member: a unicode string scalar (numpy's `np.array('female')`, dtype `<U6`).
pub fn npy_text(text: &str) -> Vec<u8> {
    let dtype = npyz::DType::Plain(format!("<U{}", text.chars().count()).parse().unwrap());
    let mut buf = Vec::new();
    let mut w = npyz::WriteOptions::<String>::new()
        .dtype(dtype)
        .shape(&[])
        .writer(&mut buf)
        .begin_nd()
        .unwrap();
    w.push(&text.to_string()).unwrap();
    w.finish().unwrap();
    buf
}

/// A zip of `members` (name without `.npy`, bytes), stored or deflated, as `numpy.savez` and
/// `numpy.savez_compressed` write them.
pub fn npz(members: &[(&str, Vec<u8>)], deflate: bool) -> Vec<u8> {
    let mut z = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let method = if deflate {
        zip::CompressionMethod::Deflated
    } else {
        zip::CompressionMethod::Stored
    };
    let options = zip::write::SimpleFileOptions::default().compression_method(method);
    for (name, bytes) in members {
        z.start_file(format!("{name}.npy"), options).unwrap();
        z.write_all(bytes).unwrap();
    }
    z.finish().unwrap().into_inner()
}

/// How a synthetic model is written.
#[derive(Debug, Clone, Copy)]
pub struct ModelSpec {
    /// 52 (SMPL-H) or 55 (SMPL-X).
    pub joints: usize,
    /// Number of shape components B.
    pub shapes: usize,
    /// Floats as `f32` (else `f64`).
    pub float32: bool,
    /// Members deflated (else stored).
    pub deflate: bool,
}

impl ModelSpec {
    /// An SMPL-X model of 16 shape components, `f64`, deflated.
    pub fn smplx() -> Self {
        Self {
            joints: SMPLX,
            shapes: 16,
            float32: false,
            deflate: true,
        }
    }

    /// The model's arrays, without the file around them (to leave some out).
    pub fn members(&self) -> Vec<(&'static str, Vec<u8>)> {
        let (p, parents) = skeleton(self.joints);
        let (j, v, b) = (self.joints, 2 * self.joints, self.shapes);
        let offset = |i: usize| Vector3::new(0.01, 0.02 * (i % 3) as f64, -0.015);
        let mut template = Vec::with_capacity(3 * v);
        let mut regressor = vec![0.0; j * v];
        let mut dirs = vec![0.0; v * 3 * b];
        for (i, pj) in p.iter().enumerate() {
            for (k, sign) in [(2 * i, 1.0), (2 * i + 1, -1.0)] {
                template.extend((pj + sign * offset(i)).iter());
                regressor[i * v + k] = 0.5;
                let at = |axis: usize, c: usize| (k * 3 + axis) * b + c;
                if b > 0 {
                    dirs[at(1, 0)] = HEIGHT_SCALE * pj.y;
                }
                if b > 1 {
                    dirs[at(0, 1)] = WIDTH_SCALE * pj.x;
                }
                for c in 2..b {
                    dirs[at(2, c)] = sign * 0.01 * c as f64;
                }
            }
        }
        let mut tree: Vec<u32> = parents.iter().map(|q| *q as u32).collect();
        tree.extend(0..j as u32);
        let f = self.float32;
        vec![
            ("v_template", npy_floats(&[v, 3], &template, f)),
            ("shapedirs", npy_floats(&[v, 3, b], &dirs, f)),
            ("J_regressor", npy_floats(&[j, v], &regressor, f)),
            ("kintree_table", npy_u32(&[2, j], &tree)),
            ("posedirs", npy_floats(&[v, 3, 9], &vec![0.0; v * 27], f)),
            (
                "weights",
                npy_floats(&[v, j], &vec![1.0 / j as f64; v * j], f),
            ),
        ]
    }

    /// The model file's bytes.
    pub fn bytes(&self) -> Vec<u8> {
        npz(&self.members(), self.deflate)
    }
}

/// An AMASS archive: poses (T × 3J axis-angle [rad]), root translations [m], shape, gender,
/// frame rate [Hz] under AMASS's SMPL-H key (`mocap_framerate`) for 52 joints and its SMPL-X
/// key (`mocap_frame_rate`) for 55.
#[derive(Debug, Clone)]
pub struct Archive {
    pub joints: usize,
    pub poses: Vec<Vec<f64>>,
    pub trans: Vec<Vector3<f64>>,
    pub betas: Vec<f64>,
    pub gender: &'static str,
    pub rate: f64,
    pub float32: bool,
    pub deflate: bool,
}

impl Archive {
    /// `frames` frames of the rest pose at the origin, 16 shape coefficients (β₀ = 0.5,
    /// β₁ = −0.4, β₅ = 0.3), female, 30 Hz, `f64`, stored.
    pub fn rest(joints: usize, frames: usize) -> Self {
        let mut betas = vec![0.0; 16];
        betas[0] = 0.5;
        betas[1] = -0.4;
        betas[5] = 0.3;
        Self {
            joints,
            poses: vec![vec![0.0; 3 * joints]; frames],
            trans: vec![Vector3::zeros(); frames],
            betas,
            gender: "female",
            rate: 30.0,
            float32: false,
            deflate: false,
        }
    }

    /// Sets joint `joint`'s axis-angle vector in frame `frame`.
    pub fn set(&mut self, frame: usize, joint: usize, axis_angle: Vector3<f64>) {
        self.poses[frame][3 * joint..3 * joint + 3].copy_from_slice(axis_angle.as_slice());
    }

    /// The archive's arrays, without the file around them.
    pub fn members(&self) -> Vec<(&'static str, Vec<u8>)> {
        let t = self.poses.len();
        let flat: Vec<f64> = self.poses.concat();
        let trans: Vec<f64> = self.trans.iter().flat_map(|v| [v.x, v.y, v.z]).collect();
        let rate_key = if self.joints == SMPLH {
            "mocap_framerate"
        } else {
            "mocap_frame_rate"
        };
        let f = self.float32;
        vec![
            ("trans", npy_floats(&[self.trans.len(), 3], &trans, f)),
            ("gender", npy_text(self.gender)),
            (rate_key, npy_floats(&[], &[self.rate], false)),
            ("betas", npy_floats(&[self.betas.len()], &self.betas, f)),
            ("poses", npy_floats(&[t, flat.len() / t.max(1)], &flat, f)),
        ]
    }

    /// The archive file's bytes.
    pub fn bytes(&self) -> Vec<u8> {
        npz(&self.members(), self.deflate)
    }

    /// A walk of `seconds` at 30 Hz: the body stood up in AMASS's Z-up world facing +X
    /// (root rotation `Rz(90°) Rx(90°)`), moving forward at 1 m/s, its hips swinging
    /// ±0.35 rad in opposition at 1 Hz, each knee bending up to 0.6 rad while its leg swings
    /// forward, the arms lowered and the elbows bent 0.3 rad; the pelvis at its template
    /// height, so that both feet reach the ground (the foot joints at height 0.02 m) when the
    /// legs pass under the body.
    pub fn walk(joints: usize, seconds: f64) -> Self {
        let rate = 30.0;
        let frames = (seconds * rate) as usize + 1;
        let mut a = Self::rest(joints, frames);
        a.betas = vec![0.0; 16];
        let up = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2)
            * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), FRAC_PI_2);
        let pelvis = skeleton(joints).0[0];
        for f in 0..frames {
            let t = f as f64 / rate;
            let phase = 2.0 * std::f64::consts::PI * t;
            let swing = 0.35 * phase.sin();
            a.set(f, 0, up.scaled_axis());
            // SMPL's hips flex about their x axis (the body's left): negative brings the
            // thigh forward.
            a.set(f, 1, Vector3::new(-swing, 0.0, 0.0));
            a.set(f, 2, Vector3::new(swing, 0.0, 0.0));
            let knee = |s: f64| 0.6 * s.max(0.0);
            a.set(f, 4, Vector3::new(knee(phase.cos()), 0.0, 0.0));
            a.set(f, 5, Vector3::new(knee(-phase.cos()), 0.0, 0.0));
            // The arms lowered 1.2 rad from the template's T-pose about z.
            a.set(f, 16, Vector3::new(0.0, 0.0, -1.2));
            a.set(f, 17, Vector3::new(0.0, 0.0, 1.2));
            a.set(f, 18, Vector3::new(0.0, -0.3, 0.0));
            a.set(f, 19, Vector3::new(0.0, 0.3, 0.0));
            // World root = trans + J₀: the pelvis at (t, 0, its template height).
            a.trans[f] = Vector3::new(t - pelvis.x, -pelvis.y, pelvis.y - pelvis.z);
        }
        a
    }
}
