//! The command line as a user meets it: the built binary, its exit codes, its outputs. A full
//! or closed stdout (`--help` and `--version` too) is one line or a quiet end, never a panic;
//! values at the edges, or past a floor that would make a run endless, are one line and exit 2.

use super::helpers::{bin, dicephys, json, scratch, stderr, Scratch};
use std::process::Stdio;

#[test]
fn bad_input_gets_one_line_and_exit_code_2() {
    let cases: &[&[&str]] = &[
        &["roll", "--block", "0x24x20"],
        &["roll", "--block", "abc"],
        &["roll", "--block", "140x24x20", "--rolls", "0"],
        &["roll", "--block", "140x24x20", "--dt", "0"],
        &["roll", "--block", "140x24x20", "--dt", "0.5"],
        &["roll", "--block", "140x24x20", "--dt", "nan"],
        &["roll", "--block", "140x24x20", "--dt", "1/0"],
        &["roll", "--block", "140x24x20", "--dt", "1/x"],
        &["roll", "--block", "140x24x20", "--friction", "-1"],
        &["roll", "--block", "140x24x20", "--restitution", "1.5"],
        &["roll", "--block", "140x24x20", "--spin", "160:31"],
        &["roll", "--block", "140x24x20", "--engine", "havok"],
        &["roll", "--block", "140x24x20", "--preset", "bullet2"],
        &["roll", "--block", "140x24x20", "--throws", "random"],
        &[
            "roll",
            "--block",
            "140x24x20",
            "--per-roll",
            "/nonexistent/dir/x.csv",
        ],
        &["roll", "--block", "20000x24x20"],
        &["paper", "--rolls", "0"],
        &["trace", "--block", "140x24x20", "--every", "0"],
        &["trace", "--block", "140x24x20", "--flight", "warp"],
        &["bench", "--rolls", "0"],
        &["bench", "--repeat", "0"],
        &["bench", "--dicephys", "/nonexistent/dicephys-2.81"],
    ];
    for args in cases {
        let out = dicephys(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?} printed to stdout");
    }
}

/// Every field a library message names comes typed and is named by its flag, the one refused
/// and the ones the message advises (issue 45: never the library's name, never re-read from
/// text): a hand's throw without its concentration, a range given to a die released at rest,
/// a plane floor given a thickness.
#[test]
fn a_message_names_every_field_it_mentions_by_its_flag() {
    for (args, says) in [
        (
            &["--throw", "hand"][..],
            "dicephys: --throw hand: needs --kappa K (",
        ),
        (
            &["--throw", "rest", "--velocity", "1:2"][..],
            "dicephys: --velocity 1:2: --throw rest releases the die at rest and uses no range; \
             leave --velocity out",
        ),
        (
            &["--floor", "plane", "--floor-thickness", "1"][..],
            "dicephys: --floor-thickness 1: the plane floor is a half-space; give --floor box",
        ),
    ] {
        let out = dicephys(&[&["roll", "--rolls", "10"][..], args].concat());
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(stderr(&out).starts_with(says), "{args:?}: {}", stderr(&out));
    }
}

/// A misspelt flag or command keeps clap's suggestion in its one line (issue 50).
#[test]
fn a_misspelt_flag_or_command_is_told_what_it_may_mean() {
    for (args, says) in [
        (&["roll", "--rols", "10"][..], "did you mean --rolls?"),
        (&["rol"][..], "did you mean roll?"),
        (&["fair", "--nul", "uniform"][..], "did you mean --null?"),
    ] {
        let out = dicephys(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
}

/// Every flag a message of the program names exists (issue 50: "add --mode 3d" named a flag
/// there is none of). Walks every string the source writes, outside comments, for `--name`,
/// and finds each in some command's `--help` (the Python crate's too, which should name none);
/// the only others are sbatch's options, which the Slurm scripts pass to sbatch.
#[test]
fn every_flag_a_message_names_exists() {
    let help = |args: &[&str]| String::from_utf8_lossy(&dicephys(args).stdout).into_owned();
    let commands = |text: &str| -> Vec<String> {
        text.lines()
            .skip_while(|l| !l.starts_with("Commands:"))
            .skip(1)
            .take_while(|l| !l.trim().is_empty())
            .filter_map(|l| l.split_whitespace().next().map(str::to_string))
            .filter(|c| c != "help")
            .collect()
    };
    let mut all = help(&["--help"]);
    for c in commands(&all.clone()) {
        let text = help(&[&c, "--help"]);
        for sub in commands(&text) {
            all += &help(&[&c, &sub, "--help"]);
        }
        all += &text;
    }
    let flags = |text: &str| -> std::collections::BTreeSet<String> {
        let b = text.as_bytes();
        let mut out = std::collections::BTreeSet::new();
        for i in 0..b.len().saturating_sub(2) {
            let starts = b[i] == b'-' && b[i + 1] == b'-' && b[i + 2].is_ascii_lowercase();
            if starts && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'-')) {
                let end = (i + 2..b.len())
                    .find(|&j| !(b[j].is_ascii_alphanumeric() || b[j] == b'-'))
                    .unwrap_or(b.len());
                out.insert(text[i..end].trim_end_matches('-').to_string());
            }
        }
        out
    };
    let known = flags(&all);
    assert!(known.contains("--rolls") && known.contains("--within") && known.len() > 80);
    let sbatch = [
        "--array",
        "--cpus-per-task",
        "--dependency",
        "--job-name",
        "--kill-on-invalid-dep",
        "--open-mode",
        "--output",
        "--parsable",
        "--requeue",
    ];
    let mut unknown = Vec::new();
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut stack = vec![root.join("src"), root.join("python/src")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            // The tests' own modules may spell anything; the program's messages may not.
            let text = text.split("#[cfg(test)]").next().unwrap_or_default();
            for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
                for f in flags(line) {
                    if !known.contains(&f) && !sbatch.contains(&f.as_str()) {
                        unknown.push(format!("{}: {f}", path.display()));
                    }
                }
            }
        }
    }
    assert!(unknown.is_empty(), "flags no command has: {unknown:#?}");
}

#[test]
fn roll_json_has_the_documented_fields_and_ignores_thread_count() {
    let base = [
        "roll",
        "--block",
        "140x22x13",
        "--2d",
        "--rolls",
        "200",
        "--seed",
        "9",
        "--json",
    ];
    let one = json(&dicephys(&[&base[..], &["--threads", "1"]].concat()));
    let two = json(&dicephys(&[&base[..], &["--threads", "2"]].concat()));
    for f in [
        "engine",
        "preset",
        "block_mm",
        "mode",
        "rolls",
        "seed",
        "dt",
        "counts",
        "unconverged",
        "failed",
        "ratio",
        "ratio_err",
        "theory_ratio",
        "steps_mean",
        "wall_s",
        "cpu_s",
        "engine_version",
    ] {
        assert!(one.get(f).is_some(), "missing {f}");
    }
    assert_eq!(one["counts"], two["counts"]);
    assert_eq!(one["steps_total"], two["steps_total"]);
    assert_eq!(one["rolls"], 200);
    assert_eq!(one["mode"], "2d");
}

#[test]
fn per_roll_csv_has_a_row_per_throw() {
    let path = std::env::temp_dir().join(format!("dicephys-per-roll-{}.csv", std::process::id()));
    let p = path.to_str().unwrap();
    let out = dicephys(&[
        "roll",
        "--block",
        "140x24x20",
        "--rolls",
        "50",
        "--per-roll",
        p,
    ]);
    assert!(out.status.success());
    let text = std::fs::read_to_string(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 51);
    assert!(
        lines[0].starts_with("index,drop_height_m,velocity_m_s,spin_rad_s,status,outcome,steps")
    );
    assert!(lines[1].starts_with("0,"));
}

#[test]
fn trace_prints_a_trajectory() {
    let out = dicephys(&[
        "trace",
        "--block",
        "140x24x20",
        "--index",
        "3",
        "--every",
        "100",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("step,time_s,x,y,z,"));
    assert!(text.lines().count() > 5);
    assert!(String::from_utf8_lossy(&out.stderr).contains("settled"));
}

#[test]
fn a_tiny_paper_run_is_complete_and_repeatable() {
    let dir = Scratch::absent("paper");
    let d = dir.to_str().unwrap();
    let run = || {
        let out = dicephys(&["paper", "--rolls", "40", "--seed", "3", "--out", d]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        // On the terminal the verdict, first and short (issue 50): at most 40 lines of at
        // most 120 characters, the theory's χ² and every simulated block in it, the report
        // named; the report itself is the file's.
        let text = String::from_utf8_lossy(&out.stdout);
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines.len() <= 40, "{text}");
        assert!(lines.iter().all(|l| l.chars().count() <= 120), "{text}");
        assert!(
            lines[0].starts_with("Pender & Uhrin (2014) reproduced"),
            "{text}"
        );
        assert!(text.contains("mdf 42.5 on 8"), "{text}");
        for block in crate::helpers::MDF_BLOCKS {
            assert!(text.contains(block), "{block}: {text}");
        }
        assert!(
            text.contains("report.md") && !text.contains("| row |"),
            "{text}"
        );
        // The reading's blocks outside 1σ on a line of their own, so that all five fit.
        assert!(
            text.contains(" within 1σ, ") && !text.contains(" MDF ("),
            "{text}"
        );
        assert!(!text.contains("; outside 1σ"), "{text}");
        let text = std::fs::read_to_string(dir.join("results.json")).unwrap();
        serde_json::from_str::<serde_json::Value>(&text).unwrap()
    };
    let a = run();
    let b = run();
    let rows = a["table"]["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 19, "every table row");
    let sims = a["simulations"].as_array().unwrap();
    assert!(sims.len() >= 10, "five blocks, 3D and 2D, per engine");
    for (x, y) in sims.iter().zip(b["simulations"].as_array().unwrap()) {
        assert_eq!(x["run"]["counts"], y["run"]["counts"]);
        assert_eq!(x["ratio"], y["ratio"]);
    }
    // report.md opens with the verdict, then its tables by subject, none of them wide (a
    // single table of 16 columns reached 290 characters).
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let sections: Vec<&str> = md.lines().filter(|l| l.starts_with("## ")).collect();
    assert_eq!(sections.first(), Some(&"## Verdict"), "{md}");
    assert!(
        sections.contains(&"## The theory against the paper's rows")
            && sections.contains(&"## Bullet against experiment"),
        "{sections:?}"
    );
    let widest = md
        .lines()
        .filter(|l| l.starts_with('|'))
        .map(|l| l.chars().count())
        .max()
        .unwrap();
    assert!(widest <= 160, "a table row of {widest} characters");
    for (fig, series) in [
        (
            "master_graph",
            &[
                "theory",
                "without a bounce",
                "printed on MDF",
                "Bullet 2D simulation",
                "Bullet 3D simulation",
            ][..],
        ),
        ("prob_2d", &["theory"][..]),
        ("len_graph", &["printed 24x20 on MDF"][..]),
        ("dreidel", &["first order"][..]),
    ] {
        let svg = std::fs::read_to_string(dir.join(format!("{fig}.svg"))).unwrap();
        assert!(
            svg.trim_start().starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
            "{fig}.svg"
        );
        assert_eq!(svg.matches("<svg").count(), svg.matches("</svg>").count());
        for name in series {
            assert!(svg.contains(name), "{fig}.svg lacks the series '{name}'");
        }
        let png = std::fs::read(dir.join(format!("{fig}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{fig}.png");
    }
    assert!(dir.join("results.csv").exists());
}

/// The library names a bad value by its field (`max_steps`); the command line names it by the
/// flag the user typed.
#[test]
fn bad_input_names_the_flag_that_was_typed() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["roll", "--block", "140x24x20", "--max-steps", "0"],
            "--max-steps 0",
        ),
        (
            &["roll", "--block", "140x24x20", "--margin", "2"],
            "--margin 2",
        ),
        (
            &["roll", "--block", "140x24x20", "--drop-height", "-1"],
            "--drop-height",
        ),
        (
            &["roll", "--block", "140x24x20", "--restitution", "1.5"],
            "--allow-restitution-above-one",
        ),
        (
            &[
                "roll",
                "--block",
                "140x24x20",
                "--throw",
                "rest",
                "--throws",
                "dicephys",
            ],
            "--source keyed",
        ),
        (
            &["paper", "--engines", "", "--out", "/nonexistent/x"],
            "--engines",
        ),
        (
            &["converge", "--budget", "0", "--out", "/nonexistent/x"],
            "--budget",
        ),
        (
            &[
                "converge",
                "--reference-budget",
                "0",
                "--out",
                "/nonexistent/x",
            ],
            "--reference-budget",
        ),
        (
            &[
                "tradeoff",
                "--reference-dt",
                "1/100",
                "--out",
                "/nonexistent/x",
            ],
            "--reference-dt 1/100",
        ),
        (
            &["stability", "--frictions", "nan", "--out", "/nonexistent/x"],
            "--frictions",
        ),
    ];
    for (args, flag) in cases {
        let out = dicephys(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(flag), "{args:?}: {err} does not name {flag}");
        assert!(!err.contains('`') && !err.contains('_'), "{args:?}: {err}");
    }
}

/// Shell completions and the manual page come from the flags themselves.
#[test]
fn completions_and_the_man_page_come_from_the_flags() {
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let out = dicephys(&["completions", shell]);
        assert!(out.status.success(), "{shell}");
        let text = String::from_utf8_lossy(&out.stdout);
        // Each shell spells a long flag its own way (fish: `-l reference-dt`).
        for word in ["dicephys", "converge", "block", "reference-dt"] {
            assert!(text.contains(word), "{shell} completions lack {word}");
        }
    }
    let out = dicephys(&["completions", "tcsh"]);
    assert_eq!(out.status.code(), Some(2));
    let man = dicephys(&["man"]);
    assert!(man.status.success());
    let text = String::from_utf8_lossy(&man.stdout);
    assert!(
        text.starts_with(".ie") || text.contains(".TH dicephys 1"),
        "{text}"
    );
    for word in ["paper", "converge", "slurm", "completions"] {
        assert!(text.contains(word), "the man page lacks {word}");
    }
}

/// Without a terminal on stderr (a log file, a cluster job's output), a long command says how
/// far it has come now and then (`DICEPHYS_PROGRESS_SECS`: here at every cell).
#[test]
fn without_a_terminal_a_study_prints_progress_lines() {
    let dir = Scratch::new("progress");
    let out = super::helpers::bin()
        .args([
            "converge",
            "--blocks",
            "140x24x20",
            "--dts",
            "1/250,1/1000",
            "--engines",
            "bullet",
            "--rolls",
            "20",
            "--json",
            "--out",
        ])
        .arg(dir.path())
        .env("DICEPHYS_PROGRESS_SECS", "0")
        .output()
        .unwrap();
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("dicephys converge: "))
        .collect();
    assert_eq!(lines.len(), 4, "a line per cell (2 dts, 3D and 2D):\n{err}");
    assert!(lines[3].contains("100 % (4 of 4 cells done), ETA"), "{err}");
    json(&out);
}

/// The ratio's relative 2σ error from a `roll --json`'s counts: 2·sqrt(1/N_b + 1/N_w).
fn two_sigma(v: &serde_json::Value) -> f64 {
    let (b, w) = (
        v["counts"]["breadth"].as_f64().unwrap(),
        v["counts"]["width"].as_f64().unwrap(),
    );
    2.0 * (1.0 / b + 1.0 / w).sqrt()
}

#[test]
fn roll_precision_stops_at_the_first_chunk_where_it_holds_on_any_thread_count() {
    // 140x30x10 in 3D lands on its breadth about 1 roll in 20: 10 % takes some 10,000 rolls.
    let base = [
        "roll",
        "--block",
        "140x30x10",
        "--precision",
        "10",
        "--seed",
        "3",
        "--json",
    ];
    let one = json(&dicephys(&[&base[..], &["--threads", "1"]].concat()));
    let two = json(&dicephys(&[&base[..], &["--threads", "2"]].concat()));
    let strip = |v: &serde_json::Value| {
        let mut v = v.clone();
        for k in ["wall_s", "cpu_s", "cpu_ms_per_roll", "threads", "checksum"] {
            v.as_object_mut().unwrap().remove(k);
        }
        v
    };
    assert_eq!(
        strip(&one),
        strip(&two),
        "the same rolls on 1 and 2 threads"
    );
    let p = &one["precision"];
    assert_eq!(p["resolved"], true);
    assert_eq!(p["asked_percent"], 10.0);
    let rolls = one["rolls"].as_u64().unwrap();
    assert_eq!(p["rolls"].as_u64(), Some(rolls));
    assert_eq!(rolls % 1000, 0, "it stops at a chunk boundary");
    let reached = two_sigma(&one);
    assert!((p["reached_percent"].as_f64().unwrap() - 100.0 * reached).abs() < 1e-9);
    assert!(reached <= 0.10);
    // One chunk fewer, the same throws: not yet resolved, so it stopped at the first boundary.
    let cap = (rolls - 1000).to_string();
    let before = json(&dicephys(
        &[&base[..], &["--threads", "2", "--rolls", &cap]].concat(),
    ));
    assert_eq!(before["precision"]["resolved"], false);
    assert!(two_sigma(&before) > 0.10, "resolved a chunk earlier");
    let needed = before["precision"]["rolls_needed"].as_u64().unwrap();
    assert!(needed > rolls - 1000, "rolls needed {needed} at {cap}");
}

#[test]
fn crosscheck_precision_rolls_the_engines_in_step_until_each_is_resolved() {
    let out = json(&dicephys(&[
        "crosscheck",
        "--block",
        "140x24x20",
        "--2d",
        "--engines",
        "bullet,rapier",
        "--precision",
        "25",
        "--seed",
        "5",
        "--json",
    ]));
    let p = &out["precision"];
    assert_eq!(p["resolved"], true);
    let runs = out["runs"].as_array().unwrap();
    let rolls = runs[0]["rolls"].as_u64().unwrap();
    assert_eq!(runs[1]["rolls"].as_u64(), Some(rolls), "in step");
    assert_eq!(rolls % 1000, 0);
    let worst = runs.iter().map(two_sigma).fold(0.0, f64::max);
    assert!(worst <= 0.25);
    assert!((p["reached_percent"].as_f64().unwrap() - 100.0 * worst).abs() < 1e-9);
    // A shard or a cluster run rolls a fixed number: --precision there is refused.
    let bad = dicephys(&["roll", "--precision", "5", "--shard", "0/2"]);
    assert_eq!(bad.status.code(), Some(2));
    let bad = dicephys(&["roll", "--precision", "0"]);
    assert_eq!(bad.status.code(), Some(2));
}

/// One name per concept: `--source` (was `--throws`), `fit --point-rolls` (was `--rolls`),
/// `--kappa K` a hand's throw everywhere. The old spellings are still read, to the same run;
/// flags that would be ignored beside another are refused, not overridden in silence.
#[test]
fn the_old_spellings_still_read_and_ignored_flags_are_refused() {
    let run = |extra: &[&str]| {
        let base = ["roll", "--block", "140x24x20", "--rolls", "100", "--json"];
        let doc = json(&dicephys(&[&base[..], extra].concat()));
        (doc["counts"].clone(), doc["spec"].clone())
    };
    assert_eq!(
        run(&["--source", "dicephys", "--faithful"]),
        run(&["--throws", "dicephys", "--faithful"])
    );
    assert_eq!(
        run(&["--kappa", "5"]),
        run(&["--throw", "hand", "--kappa", "5"])
    );
    let fit = |flag: &str| {
        let out = dicephys(&["fit", "--data", "paper", flag, "0", "--json"]);
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    // Both spellings reach the same check of the value.
    assert!(
        fit("--point-rolls").contains("rolls"),
        "{}",
        fit("--point-rolls")
    );
    assert_eq!(fit("--point-rolls"), fit("--rolls"));
    for (args, says) in [
        (
            &["--faithful", "--settle", "certificate"][..],
            "cannot be used with",
        ),
        (
            &["--faithful", "--flight", "fast"][..],
            "cannot be used with",
        ),
        (&["--audit", "--settle", "certificate"][..], "--settle"),
    ] {
        let out =
            dicephys(&[&["roll", "--block", "140x24x20", "--rolls", "10"][..], args].concat());
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{args:?}: {err}");
    }
}

#[test]
fn a_full_stdout_is_an_error_not_a_panic() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    for args in [
        &["roll", "--block", "140x24x20", "--rolls", "10", "--json"][..],
        &["trace", "--block", "140x24x20", "--max-steps", "50"][..],
        &["theory", "--table"][..],
    ] {
        let out = bin()
            .args(args)
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        assert_eq!(
            stderr(&out).trim_end().lines().count(),
            1,
            "{args:?}: {}",
            stderr(&out)
        );
    }
}

#[test]
fn help_and_version_into_a_full_stdout_fail() {
    for arg in ["--help", "--version"] {
        let out = bin()
            .arg(arg)
            .stdout(
                std::fs::OpenOptions::new()
                    .write(true)
                    .open("/dev/full")
                    .unwrap(),
            )
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{arg}: {}", stderr(&out));
    }
    // Into a pipe it succeeds.
    let out = bin().arg("--help").output().unwrap();
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn a_closed_pipe_ends_quietly() {
    let mut child = bin()
        .args(["trace", "--block", "140x24x20"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert!(stderr(&out).is_empty(), "{}", stderr(&out));
    assert_ne!(out.status.code(), Some(101), "panicked");
}

#[test]
fn inputs_at_the_edges_get_one_line_and_exit_2() {
    for args in [
        &[
            "trace",
            "--block",
            "140x24x20",
            "--throws",
            "dicephys",
            "--index",
            "18446744073709551615",
        ][..],
        &["bench", "--rolls", "18446744073709551615"][..],
        &["roll", "--block", "1e-300x1e-300x1e-300", "--rolls", "10"][..],
        &["paper", "--threads", "5000", "--rolls", "10"][..],
        &["paper", "--rolls", "18446744073709551615"][..],
    ] {
        let out = bin().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert_eq!(
            stderr(&out).trim_end().lines().count(),
            1,
            "{args:?}: {}",
            stderr(&out)
        );
    }
}

#[test]
fn time_steps_below_the_floor_and_other_endless_values_are_refused() {
    let cases: [&[&str]; 9] = [
        &["validate", "--flight-dts", "1e-12"],
        &["roll", "--block", "140x24x20", "--dt", "1e-9"],
        &["converge", "--dts", "1/1000,1e-8"],
        &["stability", "--dts", "1e-7"],
        &["roll", "--block", "140x24x20", "--density", "1e-300"],
        &["stability", "--restitutions", "1"],
        &["tradeoff", "--preroll", "1000000001"],
        &[
            "slurm",
            "stability",
            "--rolls",
            "0",
            "--tasks",
            "2",
            "--dir",
            "/nonexistent/x",
        ],
        &["merge", "/dev/zero"],
    ];
    // Run in a scratch directory, each given a minute: a value let through may never end.
    let d = scratch("floors");
    for args in cases {
        let child = bin()
            .args(args)
            .current_dir(&*d)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let id = child.id();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || tx.send(child.wait_with_output().unwrap()));
        let Ok(out) = rx.recv_timeout(std::time::Duration::from_secs(60)) else {
            unsafe { libc::kill(id as i32, libc::SIGKILL) };
            panic!("{args:?}: accepted, and still running after a minute");
        };
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert_eq!(
            stderr(&out).lines().count(),
            1,
            "{args:?}: {}",
            stderr(&out)
        );
    }
}
