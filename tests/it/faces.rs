//! Six numbered faces: `roll`'s `faces`, `--layout`, the per-roll `face` column, and `fair`,
//! on real Bullet and Rapier through the binary.

use crate::helpers::{dicephys, json, Scratch};

/// A face count from `roll --json`'s `faces`.
fn face(v: &serde_json::Value, k: &str) -> u64 {
    v["faces"][k]
        .as_u64()
        .unwrap_or_else(|| panic!("face {k}: {}", v["faces"]))
}

/// Each pair of opposite faces adds up to its side's count: 1 + 6 the length (z), 2 + 5 the
/// breadth (x), 3 + 4 the width (y), under the right-handed layout.
fn pairs_add_up(v: &serde_json::Value) {
    let c = &v["counts"];
    assert_eq!(face(v, "1") + face(v, "6"), c["length"].as_u64().unwrap());
    assert_eq!(face(v, "2") + face(v, "5"), c["breadth"].as_u64().unwrap());
    assert_eq!(face(v, "3") + face(v, "4"), c["width"].as_u64().unwrap());
}

/// A uniform cube thrown in a tumble (no preferred axis) shows each face 1/6 of the time
/// within 3σ (σ = √(p(1 − p)/n), about 0.0034 at n = 12,000), on Bullet and on Rapier; the
/// faces add up to the sides, and `--layout left` is the same rolls with 2 and 3 (5 and 4)
/// swapped. 12,000 throws on Bullet, 3,000 on Rapier (σ 0.0068).
#[test]
fn a_tumbled_cube_shows_every_face_a_sixth_of_the_time_on_both_engines() {
    for (engine, rolls) in [("bullet", "12000"), ("rapier", "3000")] {
        let args = [
            "roll", "--block", "16x16x16", "--throw", "tumble", "--rolls", rolls, "--seed", "11",
            "--engine", engine, "--json",
        ];
        let v = json(&dicephys(&args));
        pairs_add_up(&v);
        let n: u64 = (1..=6).map(|k| face(&v, &k.to_string())).sum();
        assert!(
            n as f64 > 0.99 * rolls.parse::<f64>().unwrap(),
            "{engine}: {n} at rest"
        );
        let sigma = (1.0 / 6.0 * 5.0 / 6.0 / n as f64).sqrt();
        for k in 1..=6 {
            let p = face(&v, &k.to_string()) as f64 / n as f64;
            assert!(
                (p - 1.0 / 6.0).abs() < 3.0 * sigma,
                "{engine}: face {k} {p:.4} against 1/6 ± {sigma:.4}"
            );
        }
        let left = json(&dicephys(&[&args[..], &["--layout", "left"]].concat()));
        assert_eq!(left["layout"], "left");
        for (r, l) in [
            ("1", "1"),
            ("6", "6"),
            ("2", "3"),
            ("3", "2"),
            ("5", "4"),
            ("4", "5"),
        ] {
            assert_eq!(
                face(&v, r),
                face(&left, l),
                "{engine}: right {r} against left {l}"
            );
        }
    }
}

/// In 2D the die turns about z only: its four sides' numbers (2, 3, 4, 5) and no 1 or 6. The
/// per-roll CSV's `face` column counts to the same faces, and is empty where no face settled.
#[test]
fn two_d_shows_four_faces_and_the_per_roll_column_counts_to_them() {
    let dir = Scratch::new("faces-2d");
    let csv = dir.join("rolls.csv");
    let v = json(&dicephys(&[
        "roll",
        "--block",
        "140x24x20",
        "--2d",
        "--rolls",
        "2000",
        "--json",
        "--per-roll",
        csv.to_str().unwrap(),
    ]));
    let faces = v["faces"].as_object().unwrap();
    let keys: Vec<&str> = faces.keys().map(String::as_str).collect();
    assert_eq!(keys, ["2", "3", "4", "5"]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "face")
        .expect("a face column");
    let mut counted = std::collections::BTreeMap::<String, u64>::new();
    for l in lines {
        let f = l.split(',').nth(col).unwrap().to_string();
        if !f.is_empty() {
            *counted.entry(f).or_default() += 1;
        }
    }
    for (k, c) in faces {
        assert_eq!(
            counted.get(k).copied().unwrap_or(0),
            c.as_u64().unwrap(),
            "face {k}"
        );
    }
    let c = &v["counts"];
    assert_eq!(
        faces["2"].as_u64().unwrap() + faces["5"].as_u64().unwrap(),
        c["breadth"].as_u64().unwrap()
    );
}

/// `fair`: a cube thrown in a tumble is not found biased (its χ² p above 2σ's 0.0455, every
/// face "unresolved"), and the throws a tester would need are not printed as if known; a die
/// 2 mm short along z (14x16x16: its two 16 × 16 faces, 1 and 6, are the large ones) is found
/// biased, 1 and 6 up more often than 1/6, with the throws a tester needs to see it. (Sides
/// are LENGTHxBREADTHxWIDTH, the length along z: 14x16x16 is short along z.)
#[test]
fn fair_finds_the_short_die_biased_and_the_cube_not() {
    let run = |block: &str| {
        json(&dicephys(&[
            "fair", "--block", block, "--rolls", "6000", "--seed", "5", "--json",
        ]))
    };
    let cube = run("16x16x16");
    let f = &cube["fairness"];
    assert_eq!(f["resolved"], false, "{f}");
    assert!(f["p_value"].as_f64().unwrap() > 0.0455, "{f}");
    assert!(
        f["verdict"].as_str().unwrap().starts_with("unresolved"),
        "{f}"
    );
    let numbers: Vec<u64> = f["faces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["number"].as_u64().unwrap())
        .collect();
    assert_eq!(numbers, [1, 2, 3, 4, 5, 6]);
    assert_eq!(cube["summary"]["spec"]["throws"]["style"], "tumble");
    let short = run("14x16x16");
    let f = &short["fairness"];
    assert_eq!(f["resolved"], true, "{f}");
    for face in f["faces"].as_array().unwrap() {
        let n = face["number"].as_u64().unwrap();
        let d = face["departure"].as_f64().unwrap();
        if n == 1 || n == 6 {
            assert!(d > 0.0 && face["z"].as_f64().unwrap() > 2.0, "{face}");
        } else {
            assert!(d < 0.0, "{face}");
        }
    }
    let t2 = f["throws_2sigma"].as_f64().unwrap();
    let t5 = f["throws_5sigma"].as_f64().unwrap();
    assert!(t2 > 0.0 && t2 < 6000.0 && t5 > t2, "{t2} {t5}");
}

/// `fair --out DIR` writes the `--json` document as `fairness.json` and the die map; the
/// directory is the run's: the same run again rewrites it, another is refused and nothing of
/// it is written.
#[test]
fn fair_out_writes_its_document_and_the_die_map_into_a_directory_of_its_own() {
    let dir = Scratch::absent("fair-out");
    let d = dir.to_str().unwrap();
    let args = [
        "fair", "--block", "16x16x15", "--rolls", "500", "--seed", "3", "--out", d,
    ];
    let v = json(&dicephys(&[&args[..], &["--json"]].concat()));
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("fairness.json")).unwrap()).unwrap();
    assert_eq!(file, v);
    for f in ["die_map.svg", "die_map.png", "faces.svg", "faces.png"] {
        assert!(std::fs::metadata(dir.join(f)).unwrap().len() > 1000, "{f}");
    }
    // The table as CSV too: a header and a row a face, its count the JSON's.
    let csv = std::fs::read_to_string(dir.join("fairness.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 7, "{csv}");
    assert!(rows[0].starts_with("face,label,count,p,err,null"));
    let count: u64 = rows[1].split(',').nth(2).unwrap().parse().unwrap();
    assert_eq!(count, v["fairness"]["faces"][0]["count"].as_u64().unwrap());
    assert!(dicephys(&args).status.success(), "the same run again");
    let other = dicephys(&[&args[..], &["--null", "solid-angle"]].concat());
    assert_eq!(other.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&other.stderr).contains("another `fair` run"));
    let after: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("fairness.json")).unwrap()).unwrap();
    assert_eq!(after["fairness"]["null"], "uniform");
}

/// `fair --counts`: a tester's own counts judged without a simulation, as a run's are: the χ²
/// and each face's departure by their closed forms, the quasi-static null of the die described,
/// the table as CSV; bad counts refused in one line.
#[test]
fn fair_judges_measured_counts_without_rolling() {
    let counts = [170u64, 160, 175, 168, 150, 200];
    let text: Vec<String> = counts
        .iter()
        .enumerate()
        .map(|(k, c)| format!("{}={c}", k + 1))
        .collect();
    let text = text.join(",");
    let v = json(&dicephys(&["fair", "--counts", &text, "--json"]));
    let f = &v["fairness"];
    let n: u64 = counts.iter().sum();
    let e = n as f64 / 6.0;
    let chi2: f64 = counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
    assert!((f["chi2"].as_f64().unwrap() - chi2).abs() < 1e-9, "{f}");
    assert_eq!(f["n"], n);
    assert!(v.get("summary").is_none(), "no simulation: no run summary");
    // Face 6, 200 of 1,023: z = (p − 1/6)/√(q(1 − q)/n), and the throws to see it at 2σ,
    // 4 q(1 − q)/(p − q)².
    let six = &f["faces"][5];
    let (p, q) = (200.0 / n as f64, 1.0 / 6.0);
    let z = (p - q) / (q * (1.0 - q) / n as f64).sqrt();
    assert!((six["z"].as_f64().unwrap() - z).abs() < 1e-9);
    let see = 4.0 * q * (1.0 - q) / (p - q).powi(2);
    assert!((six["throws_2sigma"].as_f64().unwrap() - see).abs() < 1e-6);
    // Against the quasi-static theory of a thick coin: the nulls its outcome shares, by label.
    let coin = json(&dicephys(&[
        "fair",
        "--counts",
        "edge=300,heads=350,tails=350",
        "--shape",
        "coin:24,8",
        "--null",
        "quasi-static",
        "--json",
    ]));
    let nulls: f64 = coin["fairness"]["faces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["null"].as_f64().unwrap())
        .sum();
    assert!((nulls - 1.0).abs() < 1e-12, "{coin}");
    // With --out: the CSV, the JSON and the faces figure.
    let dir = Scratch::absent("fair-counts");
    let d = dir.to_str().unwrap();
    assert!(dicephys(&["fair", "--counts", &text, "--out", d])
        .status
        .success());
    let csv = std::fs::read_to_string(dir.join("fairness.csv")).unwrap();
    assert_eq!(csv.lines().count(), 7, "{csv}");
    assert!(dir.join("faces.svg").exists() && dir.join("fairness.json").exists());
    for (args, says) in [
        (
            vec!["--counts", "1=17,x"],
            "--counts 1=17,x: 'x': write LABEL=COUNT",
        ),
        (
            vec!["--counts", "1=17,1=3"],
            "face '1' is empty or given twice",
        ),
        (vec!["--counts", "1=-4,2=3"], "'-4' is not a count"),
        (vec!["--counts", "1=5"], "at least two faces"),
        (
            vec!["--counts", "1=5,9=5", "--null", "quasi-static"],
            "the die has 6 (1, 2, 3, 4, 5, 6)",
        ),
        (
            vec!["--counts", "1=5,2=5", "--vary", "com_z=0:1:2"],
            "cannot be used with",
        ),
    ] {
        let o = dicephys(&[&["fair"][..], &args].concat());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err} (wanted {says})");
    }
}

/// `fair`'s own bad input: one line, exit 2, before anything rolls.
#[test]
fn fair_refuses_what_it_cannot_judge() {
    for (args, says) in [
        (
            vec![
                "fair",
                "--block",
                "140x24x20",
                "--2d",
                "--null",
                "solid-angle",
            ],
            "--null quasi-static (solid-angle)",
        ),
        (
            vec![
                "fair",
                "--block",
                "16x16x16",
                "--precision",
                "2",
                "--shard",
                "0/2",
            ],
            "--precision",
        ),
        (
            vec!["fair", "--block", "16x16x16", "--null", "fairish"],
            "fairish",
        ),
        (
            vec!["roll", "--block", "16x16x16", "--layout", "upside"],
            "upside",
        ),
    ] {
        let out = dicephys(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}

/// `fair --within PP` rolls until every face's probability is known to 2σ ≤ PP percentage
/// points, in chunks of 1,000, and says so: a cube weighted 1 mm toward face 6, asked for 1
/// point, stops at the first chunk where the largest face's 2 √(p(1 − p)/n) ≤ 0.01 (6,000
/// throws at this seed), the same on one thread as on two, and the same under the old
/// spelling `--precision` (kept for a version, with a warning).
#[test]
fn fair_rolls_every_face_to_a_precision() {
    let run_as = |threads: &str, flag: &str| {
        dicephys(&[
            "fair",
            "--block",
            "16x16x16",
            "--com",
            "0,0,-1",
            flag,
            "1",
            "--seed",
            "3",
            "--threads",
            threads,
            "--json",
        ])
    };
    let run = |threads: &str| json(&run_as(threads, "--within"));
    let v = run("2");
    let r = &v["summary"]["precision"];
    assert_eq!(r["target"], "faces");
    assert_eq!(r["resolved"], true);
    let n = v["summary"]["rolls"].as_u64().unwrap();
    assert_eq!(n % 1000, 0);
    let faces: Vec<f64> = (1..=6)
        .map(|k| v["summary"]["faces"][k.to_string()].as_f64().unwrap())
        .collect();
    let total: f64 = faces.iter().sum();
    let worst = faces
        .iter()
        .map(|c| 2.0 * (c / total * (1.0 - c / total) / total).sqrt())
        .fold(0.0, f64::max);
    assert!(worst <= 0.01, "{worst}");
    assert_eq!(run("1")["summary"]["faces"], v["summary"]["faces"]);
    let old = run_as("1", "--precision");
    let err = String::from_utf8_lossy(&old.stderr);
    assert!(err.contains("fair --precision is now --within"), "{err}");
    assert_eq!(json(&old)["summary"]["faces"], v["summary"]["faces"]);
}

/// `fair --vary`: the die at each value of one feature, the same throws at each. Its point at
/// com_z = 1 is `fair --com 0,0,1` throw for throw (the same faces); the weight toward face 1
/// brings 6 up more at 2 mm than at 0; `--out` writes bias.json and the figure; a bad
/// feature or a feature the die lacks is one line, exit 2.
#[test]
fn fair_varies_a_feature_and_draws_its_bias() {
    let dir = crate::helpers::Scratch::absent("vary");
    let base = [
        "fair", "--block", "16x16x16", "--rolls", "1500", "--seed", "8", "--json",
    ];
    let v = json(&dicephys(
        &[
            &base[..],
            &["--vary", "com_z=0:2:3", "--out", dir.to_str().unwrap()],
        ]
        .concat(),
    ));
    let points = v["points"].as_array().unwrap();
    assert_eq!(points.len(), 3);
    let one = json(&dicephys(&[&base[..], &["--com", "0,0,1"]].concat()));
    assert_eq!(points[1]["fairness"]["faces"], one["fairness"]["faces"]);
    let p6 = |i: usize| points[i]["fairness"]["faces"][5]["p"].as_f64().unwrap();
    assert!(p6(2) > p6(0) + 0.05, "{} {}", p6(0), p6(2));
    for f in ["bias.json", "bias.svg", "bias.png"] {
        assert!(dir.join(f).is_file(), "{f}");
    }
    for (extra, says) in [
        (&["--vary", "weight=0:1:3"][..], "weight"),
        (&["--vary", "pip_depth=0.5:1:2"], "no pips"),
        // Named as given (reliability round 5, class G), not as --com.
        (&["--vary", "com_z=0:9:2"], "--vary com_z=9:"),
        (
            &["--vary", "com_z=0:1:2", "--precision", "1"],
            "--precision",
        ),
    ] {
        let out = dicephys(&[&base[..], extra].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{extra:?}: {err}");
        assert!(err.contains(says), "{extra:?}: {err}");
    }
}

/// A varied die is that die rolled by itself, throw for throw, where the feature changes its
/// form: a prism's length, a d8's rounding. The scene's die is one form, so a varied shape
/// has no block left over from the die it was varied from; when it had (a scene held a shape
/// and a block beside it), these points kept the first die's block, which sets the drop, and
/// fell from its height: the prism at 30 mm from the 40 mm prism's, the rounded d8 from the
/// sharp one's.
#[test]
fn a_varied_form_is_that_die_rolled_by_itself() {
    let base = ["fair", "--rolls", "200", "--seed", "3", "--json"];
    for (die, vary, alone) in [
        (
            &["--shape", "prism:6,16,40"][..],
            "length=30:40:2",
            &["--shape", "prism:6,16,30"][..],
        ),
        (
            &["--shape", "d8"],
            "edge_radius=1:2:2",
            &["--shape", "d8", "--edge-radius", "1"],
        ),
    ] {
        let v = json(&dicephys(&[&base[..], die, &["--vary", vary]].concat()));
        let one = json(&dicephys(&[&base[..], alone].concat()));
        assert_eq!(
            v["points"][0]["fairness"]["faces"], one["fairness"]["faces"],
            "{vary}"
        );
    }
}

/// Reliability round 5, classes A and B: the numbering is the run's. `--layout left` and a
/// die file's layout used to live only in the live run: a resumed checkpoint, a merge of
/// shards read faces as a right-handed die's, shards of two layouts merged, and a die file
/// holding only a layout could not be checkpointed at all.
#[test]
fn the_numbering_is_kept_through_resume_merge_and_a_die_file() {
    let dir = Scratch::new("layout-kept");
    let args = [
        "roll", "--block", "16x16x16", "--throw", "tumble", "--rolls", "1200", "--seed", "4",
        "--json",
    ];
    let whole = json(&dicephys(&[&args[..], &["--layout", "left"]].concat()));
    assert_eq!(whole["layout"], "left");
    // Resumed from its complete checkpoint: the same faces, numbered left.
    let ck = dir.join("ck");
    let ck = ck.to_str().unwrap();
    json(&dicephys(
        &[&args[..], &["--layout", "left", "--checkpoint", ck]].concat(),
    ));
    let resumed = json(&dicephys(&["roll", "--json", "--resume", ck]));
    assert_eq!(resumed["faces"], whole["faces"]);
    assert_eq!(resumed["layout"], "left");
    // Merged shards: numbered left; shards of two layouts refused.
    let shard = |k: u32, layout: &str| {
        let v = json(&dicephys(
            &[
                &args[..],
                &["--layout", layout, "--shard", &format!("{k}/2")],
            ]
            .concat(),
        ));
        let f = dir.join(format!("{layout}{k}.json"));
        std::fs::write(&f, v.to_string()).unwrap();
        f.to_str().unwrap().to_string()
    };
    let (l0, l1, r1) = (shard(0, "left"), shard(1, "left"), shard(1, "right"));
    let merged = json(&dicephys(&["merge", "--json", &l0, &l1]));
    assert_eq!(merged["faces"], whole["faces"]);
    let mixed = dicephys(&["merge", "--json", &l0, &r1]);
    assert_eq!(mixed.status.code(), Some(2), "shards of two layouts merged");
    // A die file holding only a layout: checkpointed, and its faces its own.
    let file = dir.join("left.toml");
    std::fs::write(&file, "layout = \"left\"\n").unwrap();
    let ck2 = dir.join("ck2");
    let from_file = json(&dicephys(
        &[
            &args[..],
            &[
                "--die",
                file.to_str().unwrap(),
                "--checkpoint",
                ck2.to_str().unwrap(),
            ],
        ]
        .concat(),
    ));
    assert_eq!(from_file["faces"], whole["faces"]);
}

/// Reliability round 5, class M: `fair --shard K/N` outputs merge into the unsharded `fair`.
#[test]
fn fair_shards_merge_into_the_whole_fair() {
    let dir = Scratch::new("fair-shards");
    let args = [
        "fair", "--block", "16x16x16", "--rolls", "1200", "--seed", "6", "--json",
    ];
    let whole = json(&dicephys(&args));
    let mut files = Vec::new();
    for k in 0..2 {
        let v = json(&dicephys(
            &[&args[..], &["--shard", &format!("{k}/2")]].concat(),
        ));
        let f = dir.join(format!("f{k}.json"));
        std::fs::write(&f, v.to_string()).unwrap();
        files.push(f.to_str().unwrap().to_string());
    }
    let merged = json(&dicephys(&["merge", "--json", &files[0], &files[1]]));
    assert_eq!(merged["fairness"]["faces"], whole["fairness"]["faces"]);
    assert_eq!(merged["fairness"]["chi2"], whole["fairness"]["chi2"]);
    assert_eq!(merged["summary"]["tally"], whole["summary"]["tally"]);
}

/// Issue 50, "a fair cube that looks loaded": the paper's throw on a block whose length is not
/// its longest side warns in one line and names the tumble; a paper block and a tumble do not.
#[test]
fn the_papers_throw_on_a_cube_warns_and_names_the_tumble() {
    let stderr = |args: &[&str]| {
        let o = dicephys(args);
        assert!(o.status.success());
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let cube = stderr(&["roll", "--block", "16x16x16", "--rolls", "20", "--json"]);
    assert!(
        cube.contains("warning") && cube.contains("--throw tumble"),
        "{cube}"
    );
    assert_eq!(cube.trim_end().lines().count(), 1, "{cube}");
    let paper = stderr(&["roll", "--block", "140x24x20", "--rolls", "20", "--json"]);
    assert!(!paper.contains("warning"), "{paper}");
    let tumble = stderr(&[
        "roll", "--block", "16x16x16", "--throw", "tumble", "--rolls", "20", "--json",
    ]);
    assert!(!tumble.contains("warning"), "{tumble}");
    // The summary's first line always names the throw that made the counts.
    let header = |args: &[&str]| {
        let o = dicephys(args);
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .next()
            .unwrap_or_default()
            .to_string()
    };
    let paper = header(&["roll", "--block", "16x16x16", "--rolls", "20"]);
    assert!(paper.contains(", the paper's throw, seed 2385,"), "{paper}");
    let tumble = header(&[
        "roll", "--block", "16x16x16", "--throw", "tumble", "--rolls", "20",
    ]);
    assert!(tumble.contains(", a tumble, seed 2385,"), "{tumble}");
}

/// Issue 50, "physics that broke passes in silence": at dt = 1/30 s most rolls sink into the
/// floor, and the run says so (stderr and the JSON's `warnings`); at the defaults it says
/// nothing.
#[test]
fn broken_physics_says_so_and_the_defaults_do_not() {
    let run = |extra: &[&str]| {
        let o = dicephys(
            &[
                &[
                    "roll",
                    "--block",
                    "140x24x20",
                    "--rolls",
                    "300",
                    "--seed",
                    "1",
                    "--json",
                ][..],
                extra,
            ]
            .concat(),
        );
        let e = String::from_utf8_lossy(&o.stderr).into_owned();
        (json(&o), e)
    };
    let (v, e) = run(&["--dt", "1/30"]);
    let w = v["warnings"].as_array().expect("warnings");
    assert!(
        w.iter().any(|l| l.as_str().unwrap().contains("sank")),
        "{w:?}"
    );
    assert!(e.contains("warning") && e.contains("stability"), "{e}");
    let (v, e) = run(&[]);
    assert!(v.get("warnings").is_none(), "{}", v["warnings"]);
    assert!(!e.contains("warning"), "{e}");
}

/// Issue 74.3: each face told apart without the die map, in the text and the JSON: the
/// outward normal of the facet the die rests on to show it, and that facet's share of the
/// surface. A d8's eight facets are the eight (±1, ±1, ±1)/√3, each an eighth of the surface;
/// a coin's caps rest on ∓z, its edge on no one facet, and their shares are the cylinder's
/// areas; a 16x16x15 block's face 3 (+y up) rests on −y, a 16 × 16 face of 1472 mm² in all.
#[test]
fn fair_tells_each_face_apart_by_the_normal_and_the_area_it_rests_on() {
    let args = ["fair", "--shape", "d8", "--rolls", "200", "--seed", "1"];
    let v = json(&dicephys(&[&args[..], &["--json"]].concat()));
    let faces = v["fairness"]["faces"].as_array().unwrap();
    assert_eq!(faces.len(), 8);
    let mut normals: Vec<[i64; 3]> = Vec::new();
    for f in faces {
        let n: Vec<f64> = serde_json::from_value(f["normal"].clone()).unwrap();
        let third = 1.0 / 3f64.sqrt();
        assert!(n.iter().all(|x| (x.abs() - third).abs() < 1e-9), "{n:?}");
        normals.push([0, 1, 2].map(|k| n[k].signum() as i64));
        let share = f["area_share"].as_f64().unwrap();
        assert!((share - 0.125).abs() < 1e-9, "{share}");
    }
    normals.sort_unstable();
    normals.dedup();
    assert_eq!(normals.len(), 8, "each face its own facet");
    let text = String::from_utf8(dicephys(&args).stdout).unwrap();
    assert!(text.contains("rests on (normal x, y, z)"), "{text}");
    let row = |label: &str| {
        text.lines()
            .find(|l| l.split_whitespace().nth(1) == Some(label))
            .unwrap_or_else(|| panic!("no row {label}: {text}"))
            .to_string()
    };
    let first = &faces[0]["normal"];
    let shown = format!(
        "({:+.3}, {:+.3}, {:+.3})",
        first[0].as_f64().unwrap(),
        first[1].as_f64().unwrap(),
        first[2].as_f64().unwrap()
    );
    assert!(
        row("1").contains(&shown) && row("1").contains("12.50 %"),
        "{text}"
    );
    // roll says the same of each face, in its JSON and its text.
    let rolled = ["roll", "--shape", "d8", "--rolls", "20", "--seed", "1"];
    let r = json(&dicephys(&[&rolled[..], &["--json"]].concat()));
    assert_eq!(r["shape"]["faces"][0]["label"], faces[0]["direction"]);
    assert_eq!(r["shape"]["faces"][0]["normal"], faces[0]["normal"]);
    assert_eq!(r["shape"]["faces"][0]["area_share"], faces[0]["area_share"]);
    let said = String::from_utf8(dicephys(&rolled).stdout).unwrap();
    assert!(
        said.contains("rests on the facet of outward normal") && said.contains(&shown),
        "{said}"
    );

    // A coin's measured counts: the caps and the edge of a 24 × 2 mm cylinder.
    let coin = json(&dicephys(&[
        "fair",
        "--counts",
        "heads=48,tails=51,edge=1",
        "--shape",
        "coin:24,2",
        "--json",
    ]));
    let (cap, side) = (std::f64::consts::PI * 144.0, std::f64::consts::PI * 48.0);
    for (f, (z, share)) in coin["fairness"]["faces"].as_array().unwrap().iter().zip([
        (Some(-1.0), cap),
        (Some(1.0), cap),
        (None, side),
    ]) {
        assert_eq!(f["normal"][2].as_f64(), z, "{f}");
        let got = f["area_share"].as_f64().unwrap();
        assert!((got - share / (2.0 * cap + side)).abs() < 1e-12, "{f}");
    }

    // A cuboid, by its direction: face 3 shows +y and rests on −y.
    let block = json(&dicephys(&[
        "fair", "--block", "16x16x15", "--rolls", "60", "--seed", "1", "--json",
    ]));
    let three = &block["fairness"]["faces"][2];
    assert_eq!(three["direction"], "+y");
    assert_eq!(three["normal"], serde_json::json!([0.0, -1.0, 0.0]));
    let share = three["area_share"].as_f64().unwrap();
    assert!((share - 256.0 / 1472.0).abs() < 1e-12, "{share}");
}
