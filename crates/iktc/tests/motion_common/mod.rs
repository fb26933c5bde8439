//! A humanoid skeleton written as BVH text with the joint names of any naming family, for the
//! motion-input tests.
#![allow(dead_code)]

/// The role of a joint of the test humanoid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    Hips,
    Spine,
    Spine1,
    Spine2,
    Neck,
    Head,
    Collar,
    UpperArm,
    UpperArmTwist,
    ForeArm,
    ForeArmTwist,
    Hand,
    UpLeg,
    UpLegTwist,
    Leg,
    LegTwist,
    Foot,
    Toe,
}

/// One joint: name (`None` for an end site), parent index, offset [cm], role and side.
pub struct TestJoint {
    pub name: Option<String>,
    pub parent: Option<usize>,
    pub offset: [f64; 3],
}

/// A 1.77 m humanoid in a T-pose, Y up, facing +Z, its left side along +X, in centimetres.
/// `name(role, side)` names a joint (side `'L'`, `'R'` or `' '`); with `twist`, the upper arm,
/// forearm, thigh and shank are split in two by twist joints halfway.
pub fn humanoid(name: &dyn Fn(Role, char) -> String, twist: bool) -> Vec<TestJoint> {
    let mut j: Vec<TestJoint> = Vec::new();
    let add = |j: &mut Vec<TestJoint>, n: Option<String>, parent: Option<usize>, o: [f64; 3]| {
        j.push(TestJoint {
            name: n,
            parent,
            offset: o,
        });
        j.len() - 1
    };
    let hips = add(&mut j, Some(name(Role::Hips, ' ')), None, [0.0; 3]);
    let s0 = add(
        &mut j,
        Some(name(Role::Spine, ' ')),
        Some(hips),
        [0.0, 10.0, 0.0],
    );
    let s1 = add(
        &mut j,
        Some(name(Role::Spine1, ' ')),
        Some(s0),
        [0.0, 12.0, 0.0],
    );
    let s2 = add(
        &mut j,
        Some(name(Role::Spine2, ' ')),
        Some(s1),
        [0.0, 12.0, 0.0],
    );
    let neck = add(
        &mut j,
        Some(name(Role::Neck, ' ')),
        Some(s2),
        [0.0, 15.0, 0.0],
    );
    let head = add(
        &mut j,
        Some(name(Role::Head, ' ')),
        Some(neck),
        [0.0, 10.0, 0.0],
    );
    add(&mut j, None, Some(head), [0.0, 18.0, 0.0]);
    for (side, s) in [('L', 1.0), ('R', -1.0)] {
        let c = add(
            &mut j,
            Some(name(Role::Collar, side)),
            Some(s2),
            [5.0 * s, 10.0, 0.0],
        );
        let u = add(
            &mut j,
            Some(name(Role::UpperArm, side)),
            Some(c),
            [12.0 * s, 0.0, 0.0],
        );
        let f = if twist {
            let t = add(
                &mut j,
                Some(name(Role::UpperArmTwist, side)),
                Some(u),
                [14.0 * s, 0.0, 0.0],
            );
            add(
                &mut j,
                Some(name(Role::ForeArm, side)),
                Some(t),
                [14.0 * s, 0.0, 0.0],
            )
        } else {
            add(
                &mut j,
                Some(name(Role::ForeArm, side)),
                Some(u),
                [28.0 * s, 0.0, 0.0],
            )
        };
        let h = if twist {
            let t = add(
                &mut j,
                Some(name(Role::ForeArmTwist, side)),
                Some(f),
                [12.5 * s, 0.0, 0.0],
            );
            add(
                &mut j,
                Some(name(Role::Hand, side)),
                Some(t),
                [12.5 * s, 0.0, 0.0],
            )
        } else {
            add(
                &mut j,
                Some(name(Role::Hand, side)),
                Some(f),
                [25.0 * s, 0.0, 0.0],
            )
        };
        add(&mut j, None, Some(h), [8.0 * s, 0.0, 0.0]);
    }
    for (side, s) in [('L', 1.0), ('R', -1.0)] {
        let u = add(
            &mut j,
            Some(name(Role::UpLeg, side)),
            Some(hips),
            [10.0 * s, -5.0, 0.0],
        );
        let l = if twist {
            let t = add(
                &mut j,
                Some(name(Role::UpLegTwist, side)),
                Some(u),
                [0.0, -22.5, 0.0],
            );
            add(
                &mut j,
                Some(name(Role::Leg, side)),
                Some(t),
                [0.0, -22.5, 0.0],
            )
        } else {
            add(
                &mut j,
                Some(name(Role::Leg, side)),
                Some(u),
                [0.0, -45.0, 0.0],
            )
        };
        let l = if twist {
            let t = add(
                &mut j,
                Some(name(Role::LegTwist, side)),
                Some(l),
                [0.0, -22.5, 0.0],
            );
            add(
                &mut j,
                Some(name(Role::Foot, side)),
                Some(t),
                [0.0, -22.5, 0.0],
            )
        } else {
            add(
                &mut j,
                Some(name(Role::Foot, side)),
                Some(l),
                [0.0, -45.0, 0.0],
            )
        };
        let t = add(
            &mut j,
            Some(name(Role::Toe, side)),
            Some(l),
            [0.0, -5.0, 12.0],
        );
        add(&mut j, None, Some(t), [0.0, 0.0, 5.0]);
    }
    j
}

/// The skeleton as BVH text: the root with 6 channels, every joint 3 (ZXY), `frames` frames at
/// 30 Hz; frame `f` moves the root by `f` cm along x and turns every joint by `2·f` degrees
/// about z.
pub fn bvh_text(joints: &[TestJoint], frames: usize) -> String {
    fn write(joints: &[TestJoint], i: usize, depth: usize, out: &mut String) {
        let pad = "  ".repeat(depth);
        let j = &joints[i];
        let [x, y, z] = j.offset;
        match (&j.name, j.parent) {
            (Some(n), None) => out.push_str(&format!("ROOT {n}\n{{\n")),
            (Some(n), Some(_)) => out.push_str(&format!("{pad}JOINT {n}\n{pad}{{\n")),
            (None, _) => out.push_str(&format!("{pad}End Site\n{pad}{{\n")),
        }
        out.push_str(&format!("{pad}  OFFSET {x} {y} {z}\n"));
        match (&j.name, j.parent) {
            (Some(_), None) => out.push_str(&format!(
                "{pad}  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
            )),
            (Some(_), Some(_)) => out.push_str(&format!(
                "{pad}  CHANNELS 3 Zrotation Xrotation Yrotation\n"
            )),
            _ => {}
        }
        for c in (0..joints.len()).filter(|c| joints[*c].parent == Some(i)) {
            write(joints, c, depth + 1, out);
        }
        out.push_str(&format!("{pad}}}\n"));
    }
    let mut out = String::from("HIERARCHY\n");
    write(joints, 0, 0, &mut out);
    let named = joints.iter().filter(|j| j.name.is_some()).count();
    out.push_str(&format!(
        "MOTION\nFrames: {frames}\nFrame Time: 0.0333333\n"
    ));
    for f in 0..frames {
        let mut values = vec![f as f64, 95.0, 0.0, 0.0, 0.0, 0.0];
        for _ in 1..named {
            values.extend([2.0 * f as f64, 0.0, 0.0]);
        }
        let line: Vec<String> = values.iter().map(|v| v.to_string()).collect();
        out.push_str(&line.join(" "));
        out.push('\n');
    }
    out
}
