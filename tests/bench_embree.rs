//! `fxrt bench --against-embree` at 64×64: both throughputs and their ratio for both views,
//! and the golden model's and Embree's hit counts within 1 % of the pixels. Without embreex
//! (scripts/install-deps.sh puts it into .venv) it says "skipped: …" and passes; then fxrt
//! must refuse with exit 2 and one line naming --against-embree.

mod common;

use std::process::Command;

fn fxrt(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_fxrt")).args(args).output().expect("fxrt runs")
}

/// The numbers of a table row `VIEW THREADS FXRT EMBREE RATIO`, if `line` is one.
fn row(line: &str) -> Option<(String, Vec<f64>)> {
    let cells: Vec<&str> = line.split_whitespace().collect();
    let numbers: Vec<f64> = cells.get(1..)?.iter().map(|c| c.parse().ok()).collect::<Option<_>>()?;
    (cells.len() == 5).then(|| (cells[0].to_string(), numbers))
}

#[test]
fn bench_against_embree_prints_both_speeds_and_agreeing_hits() {
    let args = ["bench", "--against-embree", "--size", "64x64", "--repeat", "1", "--threads", "2"];
    if fxrt::render::embree::python().is_none() {
        common::say("skipped: embreex is not installed (scripts/install-deps.sh puts it into .venv)");
        let out = fxrt(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains("--against-embree") && err.contains("scripts/install-deps.sh"), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        return;
    }
    let out = fxrt(&args);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}\n{}", String::from_utf8_lossy(&out.stderr));
    let rows: Vec<(String, Vec<f64>)> = text.lines().filter_map(row).collect();
    let views: Vec<(&str, f64)> = rows.iter().map(|(v, n)| (v.as_str(), n[0])).collect();
    assert_eq!(views, [("framing", 1.0), ("framing", 2.0), ("distant", 1.0), ("distant", 2.0)], "{text}");
    for (view, n) in &rows {
        let (fxrt, embree, ratio) = (n[1], n[2], n[3]);
        assert!(fxrt > 0.0 && embree > 0.0, "{view}: {text}");
        assert!((ratio - fxrt / embree).abs() <= 0.01 * ratio.max(0.1), "{view}: {text}");
    }
    for view in ["framing", "distant"] {
        let line = text.lines().find(|l| l.starts_with(&format!("{view}: hits"))).expect("a hits line");
        assert!(line.ends_with("agree (within 1 % of pixels)"), "{line}");
    }
    assert!(text.contains("Embree 4."), "{text}");
}
