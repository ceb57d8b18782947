//! `fxrt bench exact`: the differential campaign (`verify::exact`) from the command line — its
//! options checked, a progress bar, the figures as one JSON line, and the first disagreement's
//! reproducer command.

use super::BenchArgs;
use crate::error::{Error, Result};
use crate::verify::exact::{Campaign, campaign};
use crate::verify::simulators::Simulator;

/// The campaign `bench exact` runs; errors name the option.
pub fn campaign_config(a: &BenchArgs) -> Result<Campaign> {
    if !(a.seconds.is_finite() && a.seconds > 0.0 && a.seconds < 1e9) {
        return Err(Error::param("seconds", format!("{} is out of range: must be a positive number", a.seconds)));
    }
    if a.cases == Some(0) {
        return Err(Error::param("cases", "0 is out of range: must be at least 1"));
    }
    let files = match &a.scenes {
        None => Vec::new(),
        Some(dir) => {
            let entries =
                std::fs::read_dir(dir).map_err(|e| Error::file(dir, format!("cannot read the folder: {e}")))?;
            let mut files: Vec<_> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("obj")))
                .collect();
            // Sorted: case k draws the same file on every machine.
            files.sort();
            if files.is_empty() {
                return Err(Error::file(dir, "holds no .obj file (--scenes)"));
            }
            files
        }
    };
    let hdl = match a.hdl {
        None => None,
        Some(super::FrameSim::Rust) => {
            return Err(Error::param("hdl", "rust is the campaign's own simulator: give ghdl or verilator"));
        }
        Some(super::FrameSim::Ghdl) => Some(Simulator::Ghdl),
        Some(super::FrameSim::Verilator) => Some(Simulator::Verilator),
    };
    if let Some(sim) = hdl {
        if !sim.available() {
            return Err(Error::param(
                "hdl",
                format!("{} is not installed (scripts/install-deps.sh installs it)", sim.name()),
            ));
        }
        if a.hdl_every == 0 {
            return Err(Error::param("hdl-every", "0 is out of range: must be at least 1"));
        }
    }
    Ok(Campaign {
        seed: a.seed,
        budget: std::time::Duration::from_secs_f64(a.seconds),
        max_cases: a.cases,
        files,
        out: a.out.clone(),
        hdl: hdl.map(|s| (s, a.hdl_every)),
    })
}

/// Runs the campaign; Ok(false) when the core (or the model with itself) disagreed.
pub fn bench_exact(c: &Campaign) -> Result<bool> {
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} exact: {elapsed} {msg}").expect("a valid template"),
    );
    // A case that panics is a finding, caught and written out: its message goes into the
    // reproducer, not onto the terminal in the middle of the progress bar.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let report = campaign(c, &|cases, rays| bar.set_message(format!("{cases} cases, {rays} rays compared")));
    std::panic::set_hook(hook);
    let report = report?;
    bar.finish_and_clear();
    let first = report.first.as_ref().map(|(case, dir)| serde_json::json!({ "case": case, "reproducer": dir }));
    let line = serde_json::json!({
        "seed": report.seed, "seconds": (report.seconds * 10.0).round() / 10.0,
        "cases": report.cases, "refused": report.refused, "refused_by": report.refused_by,
        "rays": report.rays, "cycles": report.cycles,
        "scenes": report.scenes, "parameter_sets": report.parameter_sets, "shapes": report.shapes,
        "inside_cameras": report.inside_cameras, "external_cases": report.external_cases, "dsp48_cases": report.dsp48_cases, "hdl_cases": report.hdl_cases,
        "findings": report.findings, "disagreeing_rays": report.disagreeing_rays, "panics": report.panics,
        "first_disagreement": first,
    });
    println!("{line}");
    if let Some((_, dir)) = &report.first {
        let command = std::fs::read_to_string(dir.join("command.txt")).unwrap_or_default();
        eprintln!(
            "fxrt: a finding (a disagreement or a panic), written to {}; reproduce with:\n{}",
            dir.display(),
            command.trim_end()
        );
    }
    Ok(report.first.is_none())
}
