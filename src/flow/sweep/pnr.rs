//! `sweep --synth --family ecp5`: each configuration's modules placed and routed on the
//! LFE5U-85F by the ECP5 flow (`flow::ecp5`, the same as `fxrt synth --family ecp5`) at the
//! sweep's clock target and seed, and what rows, results.csv and report.md show of them.

use super::eval::Row;
use super::output::Results;
use super::{Ecp5Choice, SweepSpec};
use crate::cores::top::CoreParams;
use crate::flow::ecp5::{CriticalPath, DEVICE, PACKAGE, SPEED, Timing, Tools, core_clock, module_of, place_and_route};
use crate::scene::images::SceneRoms;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// One module of a configuration, placed and routed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlacedModule {
    /// Which of `flow::ecp5::MODULES`.
    pub kind: String,
    #[serde(flatten)]
    pub timing: Timing,
}

/// How a sweep places and routes.
#[derive(Clone, Debug)]
pub struct Pnr {
    pub tools: Tools,
    pub choice: Ecp5Choice,
    pub target_mhz: u32,
    /// Build folders: DIR/KEY/MODULE (netlists, yosys and nextpnr logs, nextpnr's report).
    pub dir: PathBuf,
}

impl Pnr {
    /// Places and routes the row's modules of the core `core` (the one `--core-sim` runs);
    /// the first failure ends the row's P&R and is its error.
    pub fn place(&self, row: &mut Row, core: &CoreParams, roms: &SceneRoms) {
        for kind in &self.choice.modules {
            let (m, latency) = module_of(kind, &core.isect, core, roms);
            let dir = self.dir.join(&row.key).join(kind);
            match place_and_route(&self.tools, &m, latency, self.target_mhz as f64, self.choice.seed, &dir) {
                Ok(timing) => row.ecp5.push(PlacedModule { kind: kind.clone(), timing }),
                Err(e) => {
                    row.error = Some(e.to_string());
                    return;
                }
            }
        }
        if let (Some(run), Some(mhz)) = (&row.core, clock(row)) {
            row.mrays_per_s_at_fmax = Some((mhz / run.cycles_per_ray * 1e4).round() / 1e4);
        }
    }
}

/// The clock of the row's core: the whole core's Fmax, else the slowest placed module's (as
/// `fxrt sim --fmax-json` takes it).
pub fn clock(row: &Row) -> Option<f64> {
    core_clock(row.ecp5.iter().map(|p| (p.timing.module.as_str(), p.timing.fmax_mhz)))
}

/// What each placed module contributes to results.csv, after its kind: `core_fmax_mhz`, …
pub const FIELDS: [&str; 10] =
    ["fmax_mhz", "lut4", "ff", "wrapper_ff", "mult18", "dp16kd", "latency", "path_start", "path_end", "path_ns"];

fn cells(t: &Timing) -> [String; 10] {
    let p = &t.critical_path;
    [
        t.fmax_mhz.to_string(),
        t.lut4.to_string(),
        t.ff.to_string(),
        t.wrapper_ff.to_string(),
        t.mult18.to_string(),
        t.dp16kd.to_string(),
        t.latency_cycles.map(|l| l.to_string()).unwrap_or_default(),
        p.start.clone(),
        p.end.clone(),
        p.delay_ns.to_string(),
    ]
}

/// The columns results.csv gains (none without `--family ecp5`).
pub fn csv_columns(spec: &SweepSpec) -> Vec<String> {
    let Some(e) = &spec.ecp5 else { return Vec::new() };
    let mut v: Vec<String> = e.modules.iter().flat_map(|k| FIELDS.iter().map(move |f| format!("{k}_{f}"))).collect();
    if spec.core_sim {
        v.push("mrays_per_s_at_fmax".into());
    }
    v
}

/// A row's cells of `csv_columns` (empty where its P&R did not run or failed).
pub fn csv_cells(spec: &SweepSpec, r: &Row) -> Vec<String> {
    let Some(e) = &spec.ecp5 else { return Vec::new() };
    let mut v = Vec::new();
    for kind in &e.modules {
        match r.ecp5.iter().find(|p| &p.kind == kind) {
            Some(p) => v.extend(cells(&p.timing)),
            None => v.extend(std::iter::repeat_n(String::new(), FIELDS.len())),
        }
    }
    if spec.core_sim {
        v.push(r.mrays_per_s_at_fmax.map(|x| x.to_string()).unwrap_or_default());
    }
    v
}

/// The P&R setup, for the report: device, target, seed and the tools' versions.
pub fn setup_text(results: &Results) -> String {
    let Some(e) = &results.spec.ecp5 else { return String::new() };
    let first = results.rows.iter().flat_map(|r| r.ecp5.first()).next();
    let tools = first.map(|p| format!("; {}; {}", p.timing.yosys, p.timing.nextpnr)).unwrap_or_default();
    format!(
        "{DEVICE} ({PACKAGE}, speed grade {SPEED}), clock target {} MHz, {} ray slots × {} traversal units, \
         placement seed {}, modules {}{tools}",
        results.spec.target_mhz,
        super::report::list(&results.spec.slots),
        super::report::list(&results.spec.units),
        e.seed,
        e.modules.join(", ")
    )
}

/// A line per placed module of every row: scene, parameters, module, Fmax, resources,
/// latency, critical path, and the row's Mrays/s at Fmax on the line of the module it is
/// clocked by.
pub fn report_rows(results: &Results) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for r in &results.rows {
        let clock = clock(r);
        let mut marked = false;
        for p in &r.ecp5 {
            let t = &p.timing;
            let by_this = !marked && Some(t.fmax_mhz) == clock;
            marked |= by_this;
            let path = &t.critical_path;
            out.push(vec![
                r.scene.clone(),
                results.spec.set_text(&r.set()),
                p.kind.clone(),
                format!("{:.1}", t.fmax_mhz),
                t.lut4.to_string(),
                format!("{} ({})", t.ff, t.wrapper_ff),
                t.mult18.to_string(),
                t.dp16kd.to_string(),
                t.latency_cycles.map(|l| l.to_string()).unwrap_or_else(|| "–".into()),
                path_text(path),
                r.mrays_per_s_at_fmax.filter(|_| by_this).map(|x| format!("{x:.3}")).unwrap_or_default(),
            ]);
        }
    }
    out
}

/// A critical path for the report: start → end and its delay, marked when both ends are the
/// wrapper's (pins, XOR tree): the module itself is then at least this fast.
fn path_text(p: &CriticalPath) -> String {
    let ours = |cell: &str| cell.starts_with("u_dut");
    let wrapper = if !ours(&p.start) && !ours(&p.end) { " (the wrapper's)" } else { "" };
    format!("`{}` → `{}`, {:.2} ns{wrapper}", p.start, p.end, p.delay_ns).replace('|', "/")
}

/// Findings: per module, the range of Fmax over the sweep and where its slowest
/// configuration's critical path runs; the range of Mrays/s at Fmax.
pub fn findings(results: &Results) -> Vec<String> {
    let Some(e) = &results.spec.ecp5 else { return Vec::new() };
    let mut out = Vec::new();
    for kind in &e.modules {
        let placed: Vec<(&Row, &Timing)> = results
            .rows
            .iter()
            .filter_map(|r| r.ecp5.iter().find(|p| &p.kind == kind).map(|p| (r, &p.timing)))
            .collect();
        let by_fmax = |a: &&(&Row, &Timing), b: &&(&Row, &Timing)| a.1.fmax_mhz.total_cmp(&b.1.fmax_mhz);
        let (Some(lo), Some(hi)) = (placed.iter().min_by(by_fmax), placed.iter().max_by(by_fmax)) else { continue };
        out.push(format!(
            "ECP5 {kind}: Fmax {:.1} to {:.1} MHz over {} configurations at a {} MHz target; the slowest ({} {}): {}.",
            lo.1.fmax_mhz,
            hi.1.fmax_mhz,
            placed.len(),
            results.spec.target_mhz,
            lo.0.scene,
            super::set_label(&lo.0.set()),
            path_text(&lo.1.critical_path)
        ));
    }
    let rates: Vec<f64> = results.rows.iter().filter_map(|r| r.mrays_per_s_at_fmax).collect();
    if let (Some(lo), Some(hi)) = (rates.iter().copied().reduce(f64::min), rates.iter().copied().reduce(f64::max)) {
        let clock = if e.modules.iter().any(|m| m == "core") {
            "the whole core's Fmax"
        } else {
            "the slowest placed module's Fmax, an upper bound: place `core` for the core's own"
        };
        out.push(format!(
            "At Fmax, with one ray in flight: {lo:.3} to {hi:.3} Mrays/s ({clock} ÷ cycles per ray of the simulated core)."
        ));
    }
    out
}
