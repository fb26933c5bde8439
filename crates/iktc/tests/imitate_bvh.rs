//! A BVH file with the common naming runs through the whole pipeline with the built-in
//! `bvh_jvrc1` map: read, retarget, resample, imitate, without exceeding a limit.

use iktc::model::{jvrc1, ModelOptions};
use iktc::motion::{builtin_map, read_bvh, retarget_joint_angles, BvhReadOptions};
use iktc::sim::{run_imitate, ImitateConfig};

fn bvh_text(frames: usize) -> String {
    let mut s = String::from(
        "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\
         JOINT Spine\n {\n  OFFSET 0 10 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n\
         JOINT Neck\n  {\n   OFFSET 0 40 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n   End Site\n   {\n    OFFSET 0 20 0\n   }\n  }\n\
         JOINT RightArm\n  {\n   OFFSET -20 35 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n\
         JOINT RightForeArm\n   {\n    OFFSET -30 0 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    End Site\n    {\n     OFFSET -25 0 0\n    }\n   }\n  }\n\
         JOINT LeftArm\n  {\n   OFFSET 20 35 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n\
         JOINT LeftForeArm\n   {\n    OFFSET 30 0 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    End Site\n    {\n     OFFSET 25 0 0\n    }\n   }\n  }\n }\n}\n",
    );
    s += &format!("MOTION\nFrames: {frames}\nFrame Time: 0.033333\n");
    for f in 0..frames {
        let t = f as f64 / 30.0;
        let w = (2.0 * std::f64::consts::PI * t).sin();
        let mut v = vec![0.0, 90.0 + 3.0 * w, 0.0, 0.0, 5.0 * w, 0.0];
        v.extend([0.0, 10.0 * w, 15.0 * w]); // Spine
        v.extend([0.0, 10.0 * w, 0.0]); // Neck
        v.extend([60.0 + 20.0 * w, 0.0, 30.0 * w]); // RightArm: down from the T-pose
        v.extend([0.0, 0.0, 40.0 + 30.0 * w]); // RightForeArm
        v.extend([-60.0 - 20.0 * w, 0.0, -30.0 * w]); // LeftArm
        v.extend([0.0, 0.0, -40.0 - 30.0 * w]); // LeftForeArm
        let line: Vec<String> = v.iter().map(|x| format!("{x:.4}")).collect();
        s += &line.join(" ");
        s += "\n";
    }
    s
}

#[test]
fn bvh_clip_is_imitated_within_limits() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let clip = read_bvh(&bvh_text(61), "generated.bvh", &BvhReadOptions::default())
        .unwrap()
        .to_clip()
        .unwrap();
    let map = builtin_map("bvh_jvrc1").unwrap();
    let out = retarget_joint_angles(&clip, &robot, &map).unwrap();
    for r in &out.residuals {
        assert!(r.is_finite());
    }
    let refs = out.resample(0.005).unwrap();
    let cfg = ImitateConfig {
        narrow: Vec::new(),
        ..ImitateConfig::default()
    };
    let run = run_imitate(&robot, &refs, &cfg).unwrap();
    let s = &run.summary;
    assert_eq!(s.level_dims, vec![12, 2, 3, 1, 20]);
    assert!(s.worst_position_margin <= 1e-6);
    assert!(s.worst_velocity_margin <= 1e-6);
    assert!(s.worst_acceleration_margin <= 1e-6);
    assert!(s.foot_drift < 2e-3, "{}", s.foot_drift);
    // The arms follow: the right elbow bends (the forearm's Y rotation maps to R_ELBOW_P).
    let elbow = refs
        .joint_names
        .iter()
        .position(|n| n == "R_ELBOW_P")
        .unwrap();
    let span = refs.joints[elbow]
        .position
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        });
    assert!(span.1 - span.0 > 0.5, "R_ELBOW_P reference range {span:?}");
}
