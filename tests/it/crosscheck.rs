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
