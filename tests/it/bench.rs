//! `bench` through the binary: Ctrl-C stops it at once (and `trace`, the other command that
//! streams to stdout as it runs).

use super::helpers::{bin, exit_within};

#[test]
fn bench_and_trace_stop_on_ctrl_c() {
    // Each run is long by construction: bench at its cap of rolls on one thread; trace at
    // 1 µs a step, every step a line (over a million lines) into a pipe this test does not
    // read until it has signalled, so the run cannot end before the signal on any machine.
    for args in [
        &["bench", "--rolls", "10000000", "--threads", "1"][..],
        &[
            "trace",
            "--block",
            "140x24x20",
            "--dt",
            "1e-6",
            "--max-steps",
            "20000000",
            "--flight",
            "stepped",
        ][..],
    ] {
        stops_on_ctrl_c(args);
    }
}

/// Starts `args`, waits for its first line on stdout (its handler is installed by then and its
/// run begun), sends SIGINT, then drains stdout and expects exit 130 within a bound a slow
/// machine also meets.
fn stops_on_ctrl_c(args: &[&str]) {
    use std::io::BufRead;
    let mut child = bin()
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut out = std::io::BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    out.read_line(&mut first).unwrap();
    assert!(!first.is_empty(), "{args:?} wrote nothing");
    assert!(
        child.try_wait().unwrap().is_none(),
        "{args:?} ended before its signal"
    );
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let drain = std::thread::spawn(move || std::io::copy(&mut out, &mut std::io::sink()));
    let status = exit_within(&mut child, 5, format!("{args:?} ignored Ctrl-C"));
    let _ = drain.join();
    assert_eq!(status.code(), Some(130), "{args:?}");
}
