//! `sweep --synth --family ecp5`: each configuration's modules placed and routed on the
//! LFE5U-85F by the ECP5 flow (`fpga::ecp5`, the same as `fxrt synth --family ecp5`) at the
//! sweep's clock target and seed, and the columns results.csv gains (report.md's tables of
//! them are in `report.rs`).

use super::{Ecp5Choice, SweepSpec};
use crate::cores::top::CoreParams;
use crate::fpga::ecp5::{Timing, Tools, core_clock, module_of, place_and_route};
use crate::scene::images::SceneRoms;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// One module of a configuration, placed and routed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlacedModule {
    /// Which of `fpga::ecp5::MODULES`.
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
    /// Places and routes the modules of the core `core` (the one `--core-sim` runs) of the row
    /// `key`: the modules placed, and the first failure, which ends the row's P&R.
    pub fn place(&self, key: &str, core: &CoreParams, roms: &SceneRoms) -> (Vec<PlacedModule>, Option<String>) {
        let mut placed = Vec::new();
        for kind in &self.choice.modules {
            let (m, latency) = module_of(kind, &core.isect, core, roms);
            let dir = self.dir.join(key).join(kind);
            match place_and_route(&self.tools, &m, latency, self.target_mhz as f64, self.choice.seed, &dir) {
                Ok(timing) => placed.push(PlacedModule { kind: kind.clone(), timing }),
                Err(e) => return (placed, Some(e.to_string())),
            }
        }
        (placed, None)
    }
}

/// The clock of a row's core from its placed modules: the whole core's Fmax, else the slowest
/// placed module's (as `fxrt sim --fmax-json` takes it).
pub fn clock(placed: &[PlacedModule]) -> Option<f64> {
    core_clock(placed.iter().map(|p| (p.timing.module.as_str(), p.timing.fmax_mhz)))
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

/// A row's cells of `csv_columns` from its placed modules and Mrays/s at Fmax (empty where its
/// P&R did not run or failed).
pub fn csv_cells(spec: &SweepSpec, placed: &[PlacedModule], mrays_per_s_at_fmax: Option<f64>) -> Vec<String> {
    let Some(e) = &spec.ecp5 else { return Vec::new() };
    let mut v = Vec::new();
    for kind in &e.modules {
        match placed.iter().find(|p| &p.kind == kind) {
            Some(p) => v.extend(cells(&p.timing)),
            None => v.extend(std::iter::repeat_n(String::new(), FIELDS.len())),
        }
    }
    if spec.core_sim {
        v.push(mrays_per_s_at_fmax.map(|x| x.to_string()).unwrap_or_default());
    }
    v
}
