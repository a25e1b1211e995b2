//! Reliability round 6 (issue 69): a die of any shape counted right — every resting facet its
//! own outcome, a fair die judged fair per facet, a loaded die's own outcomes, no roll
//! silently dropped, the numbering asked applied to the die rolled.

use super::helpers::{dicephys, json, refused, scratch, stderr};
use std::path::Path;

/// A 16 mm cube, centred, outward counter-clockwise triangles.
const CUBE: &str = "v -8 -8 -8\nv 8 -8 -8\nv 8 8 -8\nv -8 8 -8\nv -8 -8 8\nv 8 -8 8\nv 8 8 8\n\
                    v -8 8 8\nf 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\n\
                    f 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

/// A run that failed with `code`, its last line of stderr saying `says` (warnings before it).
fn failed(o: &std::process::Output, code: i32, says: &str) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(code), "{e}");
    let last = e.trim_end().lines().last().unwrap_or_default();
    assert!(last.contains(says), "wanted '{says}' in: {e}");
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// The labels `roll --json` counted, in the die's order, with their counts.
pub(super) fn counted(doc: &serde_json::Value) -> Vec<(String, u64)> {
    doc["shape"]["faces"]
        .as_array()
        .expect("a die of any shape's faces")
        .iter()
        .map(|f| {
            (
                f["label"].as_str().unwrap().to_string(),
                f["count"].as_u64().unwrap(),
            )
        })
        .collect()
}

/// Item 1: an odd prism's every side is an outcome of its own (side "3" of prism:3 was never
/// reported and side "1" counted its rolls and side 3's). Each side carries a third of the
/// side rolls within 4σ (the prism is symmetric under a turn by 2π/3).
#[test]
fn every_side_of_an_odd_prism_is_counted_as_itself() {
    for n in [3u32, 5] {
        let shape = format!("prism:{n},10,10");
        let doc = json(&dicephys(&[
            "roll", "--shape", &shape, "--rolls", "600", "--seed", "1", "--json",
        ]));
        let faces = counted(&doc);
        let mut labels: Vec<&str> = faces.iter().map(|f| f.0.as_str()).collect();
        labels.sort_unstable();
        let mut want: Vec<String> = (1..=n).map(|k| k.to_string()).collect();
        want.extend(["bottom".into(), "top".into()]);
        want.sort_unstable();
        assert_eq!(labels, want, "{shape}");
        let sides: Vec<u64> = faces
            .iter()
            .filter(|f| f.0.parse::<u32>().is_ok())
            .map(|f| f.1)
            .collect();
        let total: u64 = sides.iter().sum();
        let q = 1.0 / f64::from(n);
        let sd = (total as f64 * q * (1.0 - q)).sqrt();
        for (k, c) in sides.iter().enumerate() {
            let z = (*c as f64 - total as f64 * q) / sd;
            assert!(
                z.abs() < 4.0,
                "{shape} side {}: {c} of {total} (z {z:.1})",
                k + 1
            );
        }
    }
}

/// Item 2: "fair" is per facet: a cube labelled A on one face and B on five shows A a sixth
/// of the time and is judged unbiased (it was "biased, χ² 147, B at +12σ" against 1/2 each).
/// A prism, whose faces are not alike, is noted as such against the uniform null; a stated
/// target is taken, and one naming labels the die has not is refused before anything rolls.
#[test]
fn fair_is_per_facet_and_a_target_is_a_null() {
    let d = scratch("counting-fair");
    write(&d, "cube.obj", CUBE);
    let labels: Vec<String> = [
        ([0, 0, 1], "A"),
        ([0, 0, -1], "B"),
        ([1, 0, 0], "B"),
        ([-1, 0, 0], "B"),
        ([0, 1, 0], "B"),
        ([0, -1, 0], "B"),
    ]
    .iter()
    .map(|(n, l)| {
        format!(
            "{{ normal = [{}, {}, {}], label = \"{l}\" }}",
            n[0], n[1], n[2]
        )
    })
    .collect();
    let ab = write(
        &d,
        "ab.toml",
        &format!("mesh = \"cube.obj\"\nlabels = [{}]\n", labels.join(", ")),
    );
    let doc = json(&dicephys(&[
        "fair", "--die", &ab, "--rolls", "3000", "--seed", "1", "--json",
    ]));
    let f = &doc["fairness"];
    let a = f["faces"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["direction"] == "A")
        .unwrap();
    assert!(
        (a["null"].as_f64().unwrap() - 1.0 / 6.0).abs() < 1e-12,
        "{a}"
    );
    assert!(a["z"].as_f64().unwrap().abs() < 4.0, "{a}");
    assert!(f.get("note").is_none(), "a cube's faces are alike: {f}");
    // roll's own line agrees: each label's fair share is its facets'.
    let doc = json(&dicephys(&[
        "roll", "--die", &ab, "--rolls", "600", "--seed", "1", "--json",
    ]));
    assert!(
        doc["shape"]["p_value"].as_f64().unwrap() > 1e-4,
        "{}",
        doc["shape"]
    );

    // A triangular prism against uniform: noted; against its own target, judged.
    let doc = json(&dicephys(&[
        "fair",
        "--shape",
        "prism:3,10,10",
        "--rolls",
        "300",
        "--json",
    ]));
    let note = doc["fairness"]["note"].as_str().expect("a note");
    assert!(note.contains("not alike"), "{note}");
    let doc = json(&dicephys(&[
        "fair",
        "--shape",
        "prism:3,10,10",
        "--rolls",
        "300",
        "--null",
        "1=0.3,2=0.3,3=0.3,top=1/20,bottom=1/20",
        "--json",
    ]));
    let q: Vec<f64> = doc["fairness"]["faces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["null"].as_f64().unwrap())
        .collect();
    assert!((q.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{q:?}");
    assert!(doc["fairness"].get("note").is_none());
    for (null, says) in [
        ("1=0.5,2=0.5", "leaves out"),
        ("1=0.5,7=0.5", "no face 7"),
        ("1=0.5,2=0.4", "sum to"),
    ] {
        let o = dicephys(&["fair", "--shape", "d6", "--rolls", "10", "--null", null]);
        refused(&o, 2, says);
    }
}

/// Item 4: a loaded die's outcomes are the facets it rests on at its centre of mass. The
/// designed bunny d6 hull (tests/data) rests on nine facets as a uniform solid and on six at
/// its design centre (data README): it was judged "1/9 each" with three never counted.
#[test]
fn a_loaded_die_rests_on_its_own_facets() {
    let bunny = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/bunny_d6_hull.obj");
    let faces = |extra: &[&str]| {
        let mut args = vec!["roll", "--die", bunny, "--scale", "15", "--rolls", "60"];
        args.extend_from_slice(extra);
        args.push("--json");
        counted(&json(&dicephys(&args))).len()
    };
    assert_eq!(faces(&[]), 9);
    // The design centre, (0.04829, −0.05097, 0.02015) in the mesh's units, from the hull's
    // uniform-solid centroid, times 15.
    assert_eq!(faces(&["--com", "0.87957,-2.10084,-0.22166"]), 6);
}

/// Items 3 and 15: rolls that do not come to rest on a face are never silently left out. A
/// coin with no rolling resistance at a short step cap: the verdict is refused (exit 1)
/// naming the remedies; `roll` with no roll at rest fails saying why; and a coin on Bullet
/// rolls against a hard table unless told, so that every roll ends on a face.
#[test]
fn no_roll_is_dropped_from_a_verdict() {
    let o = dicephys(&[
        "fair",
        "--shape",
        "coin:24,8.5",
        "--rolling-resistance",
        "0",
        "--max-steps",
        "3000",
        "--rolls",
        "40",
    ]);
    failed(&o, 1, "--rolling-resistance");
    let o = dicephys(&[
        "roll",
        "--shape",
        "coin:24,8.5",
        "--max-steps",
        "50",
        "--rolls",
        "5",
    ]);
    failed(&o, 1, "did not come to rest on a face");
    let doc = json(&dicephys(&[
        "roll",
        "--shape",
        "coin:24,8.5",
        "--rolls",
        "60",
        "--json",
    ]));
    assert_eq!(doc["unconverged"], 0, "{}", doc["shape"]);
    assert!((doc["spec"]["scene"]["rolling_resistance"].as_f64().unwrap() - 5e-5).abs() < 1e-12);
    // Each face's error is its own: a face seen less often has the smaller one.
    let f = doc["shape"]["faces"].as_array().unwrap();
    let (lo, hi) = (
        f.iter()
            .min_by_key(|x| x["count"].as_u64().unwrap())
            .unwrap(),
        f.iter()
            .max_by_key(|x| x["count"].as_u64().unwrap())
            .unwrap(),
    );
    if lo["count"] != hi["count"] && hi["p"].as_f64().unwrap() <= 0.5 {
        assert!(lo["p_err"].as_f64().unwrap() < hi["p_err"].as_f64().unwrap());
    }
}

/// Item 6: the numbering a die file asks for is the die's: a face map with no mesh and no
/// block numbers the default 16 mm cube (as the cuboid), and pips are drilled in it.
#[test]
fn a_die_files_numbering_is_applied_to_the_die_rolled() {
    let d = scratch("counting-map");
    let map = write(
        &d,
        "map.toml",
        "[faces]\n\"+x\" = 1\n\"-x\" = 6\n\"+y\" = 2\n\"-y\" = 5\n\"+z\" = 3\n\"-z\" = 4\n",
    );
    let doc = json(&dicephys(&[
        "roll", "--die", &map, "--rolls", "30", "--json",
    ]));
    assert!(doc.get("shape").is_none(), "the cuboid, not a d6 hull");
    assert_eq!(doc["block_mm"][0].as_f64().unwrap(), 16.0);
    assert_eq!(doc["spec"]["throws"]["style"], "tumble");
    // Face 3 is on +z: the die's own numbering counts it.
    let faces = doc["faces"].as_object().unwrap();
    assert_eq!(faces.len(), 6);
    let o = dicephys(&["roll", "--pips", "3,1", "--rolls", "5"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Item 7: `fair --resume` judges against the null the run was asked for (it judged against
/// uniform), and `--null` beside `--resume` is refused.
#[test]
fn fair_resume_keeps_its_null() {
    let d = scratch("counting-resume");
    let cp = d.join("cp").display().to_string();
    let first = json(&dicephys(&[
        "fair",
        "--shape",
        "d8",
        "--rolls",
        "40",
        "--null",
        "quasi-static",
        "--checkpoint",
        &cp,
        "--json",
    ]));
    assert_eq!(first["fairness"]["null"], "quasi-static");
    let again = json(&dicephys(&["fair", "--resume", &cp, "--json"]));
    assert_eq!(again["fairness"]["null"], "quasi-static");
    let o = dicephys(&["fair", "--resume", &cp, "--null", "uniform"]);
    refused(&o, 2, "--null");
}

/// Item 9: `fair --within` on a die of any shape stops (it rolled on to its 10M cap, "no face
/// yet"), and `roll --precision` on one is refused naming `fair --within`.
#[test]
fn fair_within_stops_on_a_shape() {
    let doc = json(&dicephys(&[
        "fair", "--shape", "d6", "--within", "5", "--json",
    ]));
    let rolls = doc["summary"]["rolls"].as_u64().unwrap();
    // 2σ ≤ 0.05 at p = 1/6 takes 4 (5/36)/0.05² ≈ 222 rolls: the first 1,000-roll chunk.
    assert_eq!(rolls, 1000, "{}", doc["summary"]["precision"]);
    let o = dicephys(&["roll", "--shape", "d6", "--precision", "2"]);
    refused(&o, 2, "fair --within");
}

/// Item 2: a fit takes a die whose labels merge facets (counts per printed number, as users of
/// mirror-pair dice have them): the cube with A on one face and B on five is fitted on its
/// two labels, each design point's counts summed over a label's facets (A about a sixth).
#[test]
fn a_fit_counts_a_die_by_label() {
    let d = scratch("counting-fit");
    write(&d, "cube.obj", CUBE);
    let labels = "[{ normal = [0, 0, 1], label = \"A\" }, { normal = [0, 0, -1], label = \"B\" }, \
                  { normal = [1, 0, 0], label = \"B\" }, { normal = [-1, 0, 0], label = \"B\" }, \
                  { normal = [0, 1, 0], label = \"B\" }, { normal = [0, -1, 0], label = \"B\" }]";
    let ab = write(
        &d,
        "ab.toml",
        &format!("mesh = \"cube.obj\"\nlabels = {labels}\n"),
    );
    let data = write(
        &d,
        "ab.csv",
        "label,surface,face_A,face_B\nab,table,50,250\n",
    );
    let out = d.join("out").display().to_string();
    let doc = json(&dicephys(&[
        "fit",
        "--data",
        &data,
        "--die",
        &ab,
        "--free",
        "e",
        "--points",
        "6",
        "--degree",
        "1",
        "--point-rolls",
        "200",
        "--no-refine",
        "--out",
        &out,
        "--json",
    ]));
    assert_eq!(
        doc["config"]["rows"][0]["labels"],
        serde_json::json!(["A", "B"])
    );
    let points = doc["designs"][0]["points"].as_array().unwrap();
    let (mut a, mut n) = (0u64, 0u64);
    for p in points {
        let c: Vec<u64> = p["counts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap())
            .collect();
        assert_eq!(c.len(), 2, "{p}");
        assert_eq!(c.iter().sum::<u64>(), 200, "every roll on A or B: {p}");
        a += c[0];
        n += 200;
    }
    // A is a sixth of the rolls within 4σ (a cube in a tumble).
    let q = 1.0 / 6.0;
    let z = (a as f64 - n as f64 * q) / (n as f64 * q * (1.0 - q)).sqrt();
    assert!(z.abs() < 4.0, "A {a} of {n} (z {z:.1})");
}

/// Item 3: a die that sinks deeper into the floor than it is thick has gone into it: a 0.1 mm
/// coin sank 45 times its thickness at 1 ms and was counted (on its edge 3.5 times as often as
/// the theory). Such rolls are failures (tunnelled), and `fair` says so as `roll` does.
#[test]
fn a_die_sunk_deeper_than_it_is_thick_is_a_failure() {
    let doc = json(&dicephys(&[
        "roll",
        "--shape",
        "coin:24,0.1",
        "--rolls",
        "200",
        "--seed",
        "1",
        "--json",
    ]));
    let tunnelled = doc["failed"]["tunnelled"].as_u64().unwrap_or(0);
    assert!(tunnelled > 0, "{}", doc["failed"]);
    let o = dicephys(&[
        "fair",
        "--shape",
        "coin:24,0.1",
        "--rolls",
        "200",
        "--seed",
        "1",
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("tunnelled"), "{text}");
}

/// The quasi-static null of a block is one formula whether `fair` rolls it or is given its
/// counts: the paper's block and a made die, each rolled, then its faces' counts judged by
/// `fair --counts`, give the same null face for face, to the last bit. (The rolled plain block
/// took Simpson's solid angles and the counts `theory::quasi_static::faces_up`, equal to
/// 3 × 10⁻¹⁵; the two verdicts' JSON differed.)
#[test]
fn a_blocks_quasi_static_null_is_the_same_rolled_or_counted() {
    for die in [
        &["--block", "140x24x20"][..],
        &["--block", "16x16x15", "--com", "0,0,-1"],
    ] {
        let rolled = json(&dicephys(
            &[
                &["fair", "--null", "quasi-static", "--rolls", "300", "--json"][..],
                die,
            ]
            .concat(),
        ));
        let faces = rolled["fairness"]["faces"].as_array().unwrap();
        let counts: Vec<String> = faces
            .iter()
            .map(|f| format!("{}={}", f["number"], f["count"]))
            .collect();
        let counted = json(&dicephys(
            &[
                &["fair", "--null", "quasi-static", "--json", "--counts"][..],
                &[counts.join(",").as_str()],
                die,
            ]
            .concat(),
        ));
        let null = |v: &serde_json::Value| -> Vec<serde_json::Value> {
            v["fairness"]["faces"]
                .as_array()
                .unwrap()
                .iter()
                .map(|f| f["null"].clone())
                .collect()
        };
        assert_eq!(null(&rolled).len(), 6, "{die:?}");
        assert_eq!(null(&rolled), null(&counted), "{die:?}");
    }
}

/// The uniform null is one for every die, counted or rolled (`theory::null::
/// uniform_label_shares`): the paper's long block counted by its numbers is noted as not made
/// to be fair, as the block rolled always was (counted, it was judged against 1/6 without a
/// word); a cube counted is not noted, nor are counts whose labels are not the die's (judged
/// against 1/N over the labels given).
#[test]
fn counts_are_judged_against_the_null_a_roll_of_the_die_is() {
    let counts = "1=10,2=12,3=9,4=11,5=30,6=28";
    let note = |args: &[&str]| {
        let doc = json(&dicephys(&[&["fair", "--json"][..], args].concat()));
        let f = &doc["fairness"];
        let q = f["faces"][0]["null"].as_f64().unwrap();
        (f.get("note").and_then(|n| n.as_str()).map(String::from), q)
    };
    let (counted, q) = note(&["--block", "140x24x20", "--counts", counts]);
    let (rolled, _) = note(&["--block", "140x24x20", "--rolls", "200"]);
    assert!(counted.as_deref().is_some_and(|n| n.contains("not alike")));
    assert_eq!(counted, rolled);
    assert!((q - 1.0 / 6.0).abs() < 1e-15, "{q}");
    assert_eq!(note(&["--block", "16x16x16", "--counts", counts]).0, None);
    let (other, q) = note(&["--block", "140x24x20", "--counts", "a=5,b=7"]);
    assert_eq!(other, None);
    assert!((q - 0.5).abs() < 1e-15, "{q}");
}
