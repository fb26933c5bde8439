//! Malformed BVH files: every error names the right line; no input makes the reader panic.

use iktc::motion::{read_bvh, BvhReadOptions};
use iktc::Error;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const BASE: [&str; 20] = [
    "HIERARCHY",                                                                // 1
    "ROOT Hips",                                                                // 2
    "{",                                                                        // 3
    "\tOFFSET 0 0 0",                                                           // 4
    "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation", // 5
    "\tJOINT Chest",                                                            // 6
    "\t{",                                                                      // 7
    "\t\tOFFSET 0 10 0",                                                        // 8
    "\t\tCHANNELS 3 Zrotation Xrotation Yrotation",                             // 9
    "\t\tEnd Site",                                                             // 10
    "\t\t{",                                                                    // 11
    "\t\t\tOFFSET 0 10 0",                                                      // 12
    "\t\t}",                                                                    // 13
    "\t}",                                                                      // 14
    "}",                                                                        // 15
    "MOTION",                                                                   // 16
    "Frames: 2",                                                                // 17
    "Frame Time: 0.0333",                                                       // 18
    "0 0 0 0 0 0 0 0 0",                                                        // 19
    "1 1 1 1 1 1 1 1 1",                                                        // 20
];

fn text(lines: &[&str]) -> String {
    lines.join("\n") + "\n"
}

/// BASE with line `n` (1-based) replaced by `with`.
fn replaced(n: usize, with: &str) -> String {
    let mut l = BASE.to_vec();
    l[n - 1] = with;
    text(&l)
}

/// BASE without line `n`.
fn removed(n: usize) -> String {
    let mut l = BASE.to_vec();
    l.remove(n - 1);
    text(&l)
}

/// BASE with `line` inserted so that it becomes line `n`.
fn inserted(n: usize, line: &str) -> String {
    let mut l = BASE.to_vec();
    l.insert(n - 1, line);
    text(&l)
}

fn error_line(t: &str) -> (usize, String) {
    match read_bvh(t, "test.bvh", &BvhReadOptions::default()) {
        Err(Error::Parse {
            line,
            message,
            source_name,
        }) => {
            assert_eq!(source_name, "test.bvh");
            (line, message)
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

fn assert_error(t: &str, line: usize, words: &str) {
    let (l, message) = error_line(t);
    assert_eq!(l, line, "{message}");
    assert!(
        message.contains(words),
        "`{message}` should contain `{words}`"
    );
}

#[test]
fn the_base_file_is_valid_also_with_crlf_and_blank_lines() {
    let clip = read_bvh(&text(&BASE), "base", &BvhReadOptions::default()).unwrap();
    assert_eq!(clip.frame_count(), 2);
    assert_eq!(clip.channel_count(), 9);
    let crlf = BASE.join("\r\n") + "\r\n";
    assert_eq!(
        read_bvh(&crlf, "base", &BvhReadOptions::default())
            .unwrap()
            .values(),
        clip.values()
    );
    let blank = inserted(19, "   ");
    assert_eq!(
        read_bvh(&blank, "base", &BvhReadOptions::default())
            .unwrap()
            .values(),
        clip.values()
    );
    // `{` on the header line.
    let mut l = BASE.to_vec();
    l[5] = "\tJOINT Chest {";
    l.remove(6);
    assert_eq!(
        read_bvh(&text(&l), "b", &BvhReadOptions::default())
            .unwrap()
            .values(),
        clip.values()
    );
}

#[test]
fn missing_braces() {
    assert_error(&removed(7), 7, "missing `{`"); // JOINT Chest followed by OFFSET
    assert_error(&removed(3), 3, "missing `{`"); // ROOT Hips followed by OFFSET
    assert_error(&removed(11), 11, "missing `{`"); // End Site followed by OFFSET
    assert_error(&removed(14), 15, "missing `}`"); // Hips not closed at MOTION (line 15 now)
    assert_error(&inserted(16, "ROOT Other"), 16, "a second `ROOT`");
}

#[test]
fn bad_hierarchy_lines() {
    assert_error(&replaced(1, "HIERARCHIE"), 1, "expected `HIERARCHY`");
    assert_error(
        &replaced(9, "\t\tCHANNELS 3 Zrotation Xrotation Wrotation"),
        9,
        "unknown channel `Wrotation`",
    );
    assert_error(
        &replaced(9, "\t\tCHANNELS 4 Zrotation Xrotation Yrotation"),
        9,
        "declares 4 channels but lists 3",
    );
    assert_error(
        &replaced(9, "\t\tCHANNELS three Zrotation Xrotation Yrotation"),
        9,
        "not a number",
    );
    assert_error(
        &replaced(9, "\t\tCHANNELS 3 Zrotation Xrotation Zrotation"),
        9,
        "listed twice",
    );
    assert_error(
        &replaced(8, "\t\tOFFSET 0 ten 0"),
        8,
        "`ten` is not a number",
    );
    assert_error(&replaced(8, "\t\tOFFSET 0 10"), 8, "OFFSET needs 3 numbers");
    assert_error(
        &replaced(8, "\t\tOFFSETT 0 10 0"),
        8,
        "unexpected `OFFSETT`",
    );
    assert_error(
        &inserted(13, "\t\t\tCHANNELS 1 Xrotation"),
        13,
        "End Site cannot have CHANNELS",
    );
    assert_error(&replaced(10, "\t\tEnd Sight"), 10, "expected `End Site`");
    assert_error(&replaced(6, "\tJOINT Hips"), 6, "used twice");
    assert_error(&replaced(6, "\tJOINT"), 6, "needs a name");
    assert_error(&removed(12), 12, "has no OFFSET"); // the End Site's `}` is line 12 now
}

#[test]
fn bad_motion_lines() {
    assert_error(
        &replaced(20, "1 1 1 1 1 1 1 1"),
        20,
        "fewer than the 9 channels",
    );
    assert_error(
        &replaced(19, "0 0 0 0 0 0 0 0 0 0"),
        19,
        "more than the 9 channels",
    );
    assert_error(
        &replaced(20, "1 1 1 1 x 1 1 1 1"),
        20,
        "frame 1, value 5: `x` is not a number",
    );
    assert_error(
        &replaced(20, "1 1 1 1 nan 1 1 1 1"),
        20,
        "frame 1, value 5: `nan` is not finite",
    );
    assert_error(&replaced(17, "Frames: 0"), 17, "zero frames");
    assert_error(&replaced(17, "Frames: many"), 17, "not a frame count");
    assert_error(&replaced(17, "Frame: 2"), 17, "expected `Frames: <number>`");
    assert_error(&replaced(18, "Frame Time: 0"), 18, "expected 0.0005 to 1 s");
    assert_error(
        &replaced(18, "Frame Time: -0.1"),
        18,
        "expected 0.0005 to 1 s",
    );
    assert_error(
        &replaced(18, "Frame Time:"),
        18,
        "expected `Frame Time: <number>`",
    );
    assert_error(
        &inserted(21, "2 2 2 2 2 2 2 2 2"),
        21,
        "more frame lines than the 2 declared",
    );
    assert_error(&replaced(16, "MOTIONS"), 16, "expected `MOTION`");
}

#[test]
fn truncated_files() {
    assert_error(
        &text(&BASE[..19]),
        19,
        "truncated file: 2 frames declared at line 17, 1 found",
    );
    assert_error(
        &text(&BASE[..18]),
        18,
        "truncated file: 2 frames declared at line 17, 0 found",
    );
    assert_error(&text(&BASE[..17]), 17, "`Frame Time:` (truncated file)");
    assert_error(&text(&BASE[..16]), 16, "`Frames:` (truncated file)");
    assert_error(&text(&BASE[..15]), 15, "before `MOTION` (truncated file)");
    assert_error(&text(&BASE[..9]), 9, "inside joint `Chest`");
    assert_error(&text(&BASE[..2]), 2, "truncated file");
    let (line, _) = error_line("");
    assert_eq!(line, 0);
}

/// No prefix of a valid file and no random corruption makes the reader panic.
#[test]
fn never_panics_on_corrupt_input() {
    let base = text(&BASE);
    for end in 0..=base.len() {
        let _ = read_bvh(&base[..end], "prefix", &BvhReadOptions::default());
    }
    let alphabet: Vec<char> =
        "{}0123456789-.eE \n\tXYZpositionrtJOINTEndSiteROOTMOTIONFrames:Time9"
            .chars()
            .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(1234);
    let mut ok = 0;
    for _ in 0..3000 {
        let mut chars: Vec<char> = base.chars().collect();
        for _ in 0..rng.random_range(1..4) {
            let i = rng.random_range(0..chars.len());
            match rng.random_range(0..3) {
                0 => chars[i] = alphabet[rng.random_range(0..alphabet.len())],
                1 => {
                    chars.remove(i);
                }
                _ => chars.insert(i, alphabet[rng.random_range(0..alphabet.len())]),
            }
        }
        let t: String = chars.into_iter().collect();
        if read_bvh(&t, "fuzz", &BvhReadOptions::default()).is_ok() {
            ok += 1;
        }
    }
    // Some corruptions are harmless (a digit changed), most are not.
    assert!(ok > 0 && ok < 3000);
    // Huge declared frame counts do not allocate up front.
    let huge = replaced(17, "Frames: 18446744073709551615");
    assert!(read_bvh(&huge, "huge", &BvhReadOptions::default()).is_err());
}
