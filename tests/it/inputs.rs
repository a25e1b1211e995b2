//! Issue 69's input checks and messages, as a user meets them: a value that cannot be right
//! is one line on stderr and exit code 2 before anything runs, with nothing written, and says
//! what is wrong in the user's own terms. Every run here is a few rolls at most.

use super::helpers::{dicephys, json, refused, scratch, stderr};
use std::path::Path;

/// The same cube as `shapes::cube_obj`: side 16 mm, eight corners, six quads.
const CUBE: &str = "v -8 -8 -8\nv 8 -8 -8\nv -8 8 -8\nv 8 8 -8\nv -8 -8 8\nv 8 -8 8\nv -8 8 8\n\
                    v 8 8 8\nf 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";

/// The cube's six labels, as a die file gives them, and `extra` lines after them.
fn labelled(extra: &str) -> String {
    format!(
        "mesh = \"cube.obj\"\nlabels = [\n{{ normal = [0, 0, 1], label = \"1\" }},\n\
         {{ normal = [0, 0, -1], label = \"6\" }},\n{{ normal = [1, 0, 0], label = \"2\" }},\n\
         {{ normal = [-1, 0, 0], label = \"5\" }},\n{{ normal = [0, 1, 0], label = \"3\" }},\n\
         {{ normal = [0, -1, 0], label = \"4\" }},\n{extra}]\n"
    )
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

/// Item 12: a `fair --vary` whose values the die cannot take (a pip depth of 0) is refused
/// before its directory is claimed, so the corrected run is not refused as "another run";
/// a finished run, and a refused one, leave no lock behind.
#[test]
fn a_refused_vary_writes_nothing_and_a_finished_fair_leaves_no_lock() {
    let d = scratch("vary-refused");
    let out = d.join("o");
    let o = out.to_str().unwrap();
    let base = [
        "fair", "--block", "16x16x16", "--pips", "3,1", "--rolls", "5",
    ];
    let bad = dicephys(&[&base[..], &["--vary", "pip_depth=0:1.5:4", "--out", o]].concat());
    refused(&bad, 2, "--vary pip_depth=0");
    assert!(!out.exists(), "a refused run wrote {}", out.display());
    // In 2D the quasi-static null is refused before anything is written, too.
    let bad = dicephys(&[
        "fair",
        "--block",
        "16x16x16",
        "--2d",
        "--null",
        "quasi-static",
        "--vary",
        "com_z=0:1:2",
        "--rolls",
        "5",
        "--out",
        o,
    ]);
    refused(&bad, 2, "--null quasi-static");
    assert!(!out.exists(), "a refused run wrote {}", out.display());
    let good = dicephys(&[&base[..], &["--vary", "pip_depth=0.5:1:2", "--out", o]].concat());
    assert!(good.status.success(), "{}", stderr(&good));
    assert!(out.join("bias.json").exists());
    assert!(!out.join("lock").exists(), "a finished run left its lock");
    // Measured counts, and a rolled verdict, leave none either.
    let counted = d.join("c");
    let c = counted.to_str().unwrap();
    let good = dicephys(&["fair", "--counts", "1=3,2=4", "--out", c]);
    assert!(good.status.success(), "{}", stderr(&good));
    assert!(counted.join("fairness.csv").exists());
    assert!(
        !counted.join("lock").exists(),
        "a finished run left its lock"
    );
}

/// Item 8: counts too large to add are refused with why, never wrapped into a NaN verdict;
/// a count of 22 digits is "too large", not "not a count".
#[test]
fn fair_counts_too_large_are_refused_not_wrapped() {
    let max = u64::MAX.to_string();
    let o = dicephys(&["fair", "--counts", &format!("1={max},2={max}")]);
    refused(&o, 2, "too large");
    let o = dicephys(&["fair", "--counts", "1=1234567890123456789012,2=3"]);
    refused(&o, 2, "'1234567890123456789012' is too large a count");
    let o = dicephys(&["fair", "--counts", "1=600000000000,2=600000000000"]);
    refused(&o, 2, "too large");
    // A label a report cannot write, or a count cannot name, is refused.
    let o = dicephys(&["fair", "--counts", "a\u{7}=1,b=2"]);
    refused(&o, 2, "control character");
}

/// Items 8 and 13: a die file's labels that cannot be named or written, and normals that are
/// no direction, name the same facet twice or no resting facet, are refused, naming the
/// label and the die file (not only its mesh).
#[test]
fn a_die_files_bad_labels_and_normals_are_refused_naming_the_file() {
    let d = scratch("labels");
    write(&d, "cube.obj", CUBE);
    let good = write(&d, "good.toml", &labelled(""));
    let v = json(&dicephys(&[
        "roll", "--die", &good, "--rolls", "3", "--json",
    ]));
    assert_eq!(v["rolls"], 3);
    for (name, extra, says) in [
        (
            "dup",
            "{ normal = [0, 0, 2], label = \"9\" },\n",
            "labels '1' and '9' have the same normal",
        ),
        (
            "zero",
            "{ normal = [0, 0, 0], label = \"7\" },\n",
            "label '7': its normal [0, 0, 0] is not a direction",
        ),
        (
            "inf",
            "{ normal = [inf, 0, 0], label = \"7\" },\n",
            "label '7': its normal [inf, 0, 0] is not a direction",
        ),
        (
            "nan",
            "{ normal = [nan, 1, 0], label = \"7\" },\n",
            "label '7': its normal [NaN, 1, 0] is not a direction",
        ),
        (
            "nomatch",
            "{ normal = [1, 1, 1], label = \"7\" },\n",
            "label '7': its normal (0.5774, 0.5774, 0.5774) is no resting facet's",
        ),
    ] {
        let file = write(&d, &format!("{name}.toml"), &labelled(extra));
        let o = dicephys(&["roll", "--die", &file, "--rolls", "3"]);
        refused(&o, 2, &format!("--die {file}: cube.obj: {says}"));
    }
    for (label, says) in [
        ("", "is empty"),
        ("a,b", "holds ',' or '='"),
        ("a=b", "holds ',' or '='"),
        ("a\\nb", "control character"),
    ] {
        let text = labelled("").replace("label = \"1\"", &format!("label = \"{label}\""));
        let file = write(&d, "label.toml", &text);
        let o = dicephys(&["roll", "--die", &file, "--rolls", "3"]);
        refused(&o, 2, says);
    }
}

/// Item 14: what would be ignored is refused: a layout beside a die of any shape, a mesh's
/// keys without a mesh, an empty die file, simulation flags beside measured counts, a face of
/// two vertices, a mesh of two bodies; a non-convex mesh rolls with one note.
#[test]
fn what_would_be_ignored_is_refused() {
    let d = scratch("ignored");
    let cube = write(&d, "cube.obj", CUBE);
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec![
                "--shape".into(),
                "d20".into(),
                "--layout".into(),
                "left".into(),
            ],
            "--layout left",
        ),
        (
            vec![
                "--die".into(),
                cube.clone(),
                "--layout".into(),
                "left".into(),
            ],
            "--layout left",
        ),
        (
            vec!["--die".into(), write(&d, "labels.toml", "labels = []\n")],
            "give its mesh",
        ),
        (
            vec!["--die".into(), write(&d, "scale.toml", "scale = 2.0\n")],
            "give its mesh",
        ),
        (
            vec!["--die".into(), write(&d, "reads.toml", "reads = \"up\"\n")],
            "give its mesh",
        ),
        (
            vec![
                "--die".into(),
                write(
                    &d,
                    "layout.toml",
                    "mesh = \"cube.obj\"\nlayout = \"left\"\n",
                ),
            ],
            "a mesh's faces show its labels",
        ),
        (
            vec!["--die".into(), write(&d, "empty.toml", "")],
            "the die file is empty",
        ),
        (
            vec!["--die".into(), write(&d, "comment.toml", "# nothing\n")],
            "the die file is empty",
        ),
        (
            vec!["--die".into(), "/dev/null".into()],
            "the die file is empty",
        ),
        (
            vec![
                "--die".into(),
                write(&d, "two.obj", &format!("{CUBE}v 0 0 0\nf 1 2\n")),
            ],
            "line 16: a face with 2 vertices",
        ),
    ];
    for (args, says) in &cases {
        let mut a = vec!["roll", "--rolls", "3"];
        a.extend(args.iter().map(String::as_str));
        refused(&dicephys(&a), 2, says);
    }
    for flag in [
        &["--rolls", "10"][..],
        &["--engine", "rapier"],
        &["--throw", "paper"],
        &["--seed", "3"],
    ] {
        let o = dicephys(&[&["fair", "--counts", "1=3,2=4"][..], flag].concat());
        refused(&o, 2, &format!("cannot be used with '{}", flag[0]));
    }
}

/// Item 14: a mesh of two bodies is refused; a non-convex one rolls on its hull, with one
/// note saying so.
#[test]
fn two_bodies_are_refused_and_a_dented_mesh_rolls_with_a_note() {
    let d = scratch("bodies");
    let cube = write(&d, "cube.obj", CUBE);
    // Two cubes side by side: two bodies in one mesh.
    let mut twin = CUBE.to_string();
    for l in CUBE.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        twin += &match w[0] {
            "v" => format!(
                "v {} {} {}\n",
                w[1].parse::<f64>().unwrap() + 40.0,
                w[2],
                w[3]
            ),
            _ => format!(
                "f {}\n",
                w[1..]
                    .iter()
                    .map(|i| (i.parse::<u32>().unwrap() + 8).to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            ),
        };
    }
    let twin = write(&d, "twin.obj", &twin);
    refused(
        &dicephys(&["roll", "--die", &twin, "--rolls", "3"]),
        2,
        "the mesh is 2 separate bodies",
    );
    // The cube with a dent in its top: rolls on its hull, with one note.
    let dent = CUBE.replace("f 5 6 8 7\n", "") + "v 0 0 4\nf 5 6 9\nf 6 8 9\nf 8 7 9\nf 7 5 9\n";
    let dent = write(&d, "dent.obj", &dent);
    let o = dicephys(&["roll", "--die", &dent, "--rolls", "3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let notes: Vec<String> = stderr(&o)
        .lines()
        .filter(|l| l.contains("is not convex"))
        .map(String::from)
        .collect();
    assert_eq!(notes.len(), 1, "{}", stderr(&o));
    assert!(notes[0].contains("rolls on its hull"), "{}", notes[0]);
    // The plain cube gets none.
    let o = dicephys(&["roll", "--die", &cube, "--rolls", "3"]);
    assert!(!stderr(&o).contains("not convex"), "{}", stderr(&o));
}

/// Item 16: messages that say what is true, in the user's terms.
#[test]
fn messages_say_what_is_true_in_the_users_terms() {
    let d = scratch("messages");
    write(&d, "cube.obj", CUBE);
    let cases: &[(&[&str], &str)] = &[
        (&["roll", "--shape", "d7"], "d20, coin:D,H or prism:N,D,L"),
        (&["roll", "--shape", "prism:1000,10,10"], "from 3 to 253"),
        (
            &["roll", "--shape", "prism:5,10,1e9"],
            "L = 1000000000 mm is too long",
        ),
        (
            &["roll", "--scale", "-1"],
            "--scale -1: must be a positive factor",
        ),
        (
            &["roll", "--shape", "d20", "--size", "-1"],
            "--size -1: must be a positive",
        ),
        (
            &["fair", "--shape", "d20", "--vary", "pip_depth=0.5:1:2"],
            "vary com_x, com_y or com_z",
        ),
    ];
    for (args, says) in cases {
        refused(&dicephys(args), 2, says);
    }
    // Advice names only flags that apply beside a shape.
    let o = dicephys(&["roll", "--shape", "d20", "--size", "-1"]);
    assert!(!stderr(&o).contains("--scale"), "{}", stderr(&o));
    let o = dicephys(&["fair", "--shape", "d20", "--vary", "pip_depth=0.5:1:2"]);
    assert!(!stderr(&o).contains("--pips"), "{}", stderr(&o));
    // An OBJ with a byte-order mark, and with comments at the ends of its lines, reads.
    let bom = write(&d, "bom.obj", &format!("\u{feff}{CUBE}"));
    let commented: String = CUBE.lines().map(|l| format!("{l} # a comment\n")).collect();
    let commented = write(&d, "commented.obj", &commented);
    for mesh in [bom, commented] {
        let v = json(&dicephys(&[
            "roll", "--die", &mesh, "--rolls", "3", "--json",
        ]));
        assert_eq!(v["rolls"], 3, "{mesh}");
    }
    // A count of 22 digits is too large; '-' in a face's column is not said to be allowed.
    let head = "label,surface,length_mm,breadth_mm,width_mm,mode";
    let big = write(
        &d,
        "big.csv",
        &format!("{head},length_vertical,breadth_vertical,width_vertical\nA,felt,140,24,20,3d,1,2,1234567890123456789012\n"),
    );
    let out = d.join("fit-out");
    let out = out.to_str().unwrap();
    refused(
        &dicephys(&["fit", "--data", &big, "--out", out]),
        2,
        "'1234567890123456789012' is too large a count",
    );
    let dash = write(
        &d,
        "dash.csv",
        &format!(
            "{head},face_1,face_2,face_3,face_4,face_5,face_6\nA,felt,16,16,16,3d,1,2,3,4,5,-\n"
        ),
    );
    let o = dicephys(&["fit", "--data", &dash, "--out", out]);
    refused(&o, 2, "'-' is not a count (a whole number)");
    assert!(!stderr(&o).contains("or '-'"), "{}", stderr(&o));
    // A range's refusal quotes the range's own numbers, not a value between them.
    let rows = write(
        &d,
        "rows.csv",
        &format!("{head},length_vertical,breadth_vertical,width_vertical\nA,felt,140,24,20,3d,1,2,3\nB,felt,140,22,13,3d,1,2,3\n"),
    );
    let o = dicephys(&[
        "fit",
        "--data",
        &rows,
        "--free",
        "e,pip_depth",
        "--pips",
        "3,1",
        "--range",
        "pip_depth=0.2:3",
        "--out",
        out,
    ]);
    refused(&o, 2, "its pip depth 3 mm");
    // A die of any shape has no pips: the advice is not --pips, which it refuses.
    let coin = write(
        &d,
        "coin.csv",
        "label,surface,face_heads,face_tails,face_edge\nc,felt,10,12,1\nd,wood,10,12,2\n",
    );
    let o = dicephys(&[
        "fit",
        "--data",
        &coin,
        "--shape",
        "coin:24,2",
        "--free",
        "e,pip_depth",
        "--out",
        out,
    ]);
    refused(&o, 2, "a die of any shape has no pips");
    assert!(!stderr(&o).contains("--pips"), "{}", stderr(&o));
    assert!(!d.join("fit-out").exists());
}
