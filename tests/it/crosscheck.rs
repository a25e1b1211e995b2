//! `crosscheck` through the binary: Ctrl-C stops it with exit 130.

use super::helpers::{interrupted, stderr, ENDLESS_ROLLS};

#[test]
fn crosscheck_stops_when_asked() {
    let out = interrupted(
        &[
            "crosscheck",
            "--block",
            "140x24x20",
            "--rolls",
            ENDLESS_ROLLS,
        ],
        libc::SIGINT,
        1500,
    );
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
}

/// `crosscheck` runs under `laws` unless `--preset` is given (issue 46: only under `laws` is
/// each engine held to the same closed forms); `roll`, and `crosscheck --faithful`, keep the
/// paper's dicephys281.
#[test]
fn crosscheck_runs_under_the_laws_preset_unless_told_otherwise() {
    let preset = |args: &[&str]| -> Vec<String> {
        let out = crate::helpers::dicephys(args);
        assert!(out.status.success(), "{}", stderr(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        match v.get("runs") {
            Some(runs) => runs
                .as_array()
                .unwrap()
                .iter()
                .map(|r| r["preset"].as_str().unwrap().to_string())
                .collect(),
            None => vec![v["preset"].as_str().unwrap().to_string()],
        }
    };
    let base = ["--block", "16x16x16", "--rolls", "10", "--json"];
    let cc = |extra: &[&str]| {
        let mut a = vec!["crosscheck"];
        a.extend_from_slice(&base);
        a.extend_from_slice(extra);
        preset(&a)
    };
    assert_eq!(cc(&[]), ["laws", "laws"]);
    assert_eq!(
        cc(&["--preset", "dicephys281"]),
        ["dicephys281", "dicephys281"]
    );
    // --faithful is DicePhys as the paper ran it, preset and all.
    assert_eq!(cc(&["--faithful"]), ["dicephys281", "dicephys281"]);
    let mut roll = vec!["roll"];
    roll.extend_from_slice(&base);
    assert_eq!(preset(&roll), ["dicephys281"]);
}
