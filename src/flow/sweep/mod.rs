//! `fxrt sweep`: image error and hardware cost over lists of n, m, T, C and E, for one or more
//! scenes (seed 001 figures 2.7–2.9, seed 003's edge shift).
//!
//! A sweep is a `SweepSpec` (what the user asked for, independent of where it runs), expanded
//! into a `Plan` (configurations numbered 0..N, and the parameter sets that are invalid
//! together). Each configuration is evaluated once and cached by its key; a shard evaluates
//! the configurations with index ≡ I−1 (mod N); `merge` joins shards. The outputs are a
//! function of (spec, rows) alone, so a merged sweep is byte-identical to an unsharded one.

pub mod axis;
pub mod eval;
pub mod grid;
pub mod output;
pub mod plots;
pub mod pnr;
pub mod report;
pub mod run;
pub mod slurm;
pub mod summary;

use crate::error::{Error, Result};
pub use crate::model::camera::CameraSpec;
use crate::params::{EdgeShift, Params, TreeSplit};
use crate::scene::SceneSource;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A scene of the sweep, as the user named it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SceneSpec {
    Builtin(String),
    Obj(PathBuf),
}

impl SceneSpec {
    pub fn source(&self) -> SceneSource {
        match self {
            SceneSpec::Builtin(b) => SceneSource::Builtin(b.clone()),
            SceneSpec::Obj(p) => SceneSource::Obj(p.clone()),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepSpec {
    pub scenes: Vec<SceneSpec>,
    pub camera: CameraSpec,
    pub n: Vec<u32>,
    pub m: Vec<u32>,
    pub t: Vec<u32>,
    pub c: Vec<u32>,
    pub edge_shift: Vec<EdgeShift>,
    pub leaf_size: u32,
    pub stack_depth: u32,
    /// The BIH's split (`--tree`; absent from results.json when `middle`, so older sweeps,
    /// all middle-split, read back the same).
    #[serde(default = "TreeSplit::absent", skip_serializing_if = "TreeSplit::is_middle")]
    pub tree: TreeSplit,
    /// Vary one parameter at a time around the base set instead of the cross product.
    pub one_at_a_time: bool,
    /// Also synthesise every configuration's core with yosys.
    pub synth: bool,
    /// Also run every configuration's frame through the whole core in the Rust simulator.
    pub core_sim: bool,
    /// The clock the cores are pipelined for, MHz (`--target-mhz`; absent from results.json
    /// at the default, so older sweeps read back the same).
    #[serde(default = "default_target_mhz", skip_serializing_if = "is_default_target_mhz")]
    pub target_mhz: u32,
    /// Ray slots per traversal unit and traversal units of every core (`--slots`, `--units`;
    /// absent from results.json at the defaults, so older sweeps read back the same).
    #[serde(default = "default_slots", skip_serializing_if = "is_default_slots")]
    pub slots: u32,
    #[serde(default = "default_units", skip_serializing_if = "is_default_units")]
    pub units: u32,
    /// `--synth --family ecp5`: place and route on the LFE5U-85F instead of Virtex-5 area.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ecp5: Option<Ecp5Choice>,
}

fn default_target_mhz() -> u32 {
    crate::cores::clock::DEFAULT_TARGET_MHZ
}

fn is_default_target_mhz(mhz: &u32) -> bool {
    *mhz == default_target_mhz()
}

fn default_slots() -> u32 {
    crate::cores::top::DEFAULT_SLOTS
}

fn is_default_slots(k: &u32) -> bool {
    *k == default_slots()
}

fn default_units() -> u32 {
    crate::cores::top::DEFAULT_UNITS
}

fn is_default_units(u: &u32) -> bool {
    *u == default_units()
}

impl SweepSpec {
    /// Whether the cores have the default ray slots and units.
    pub fn default_core_shape(&self) -> bool {
        is_default_slots(&self.slots) && is_default_units(&self.units)
    }
}

/// What `sweep --synth --family ecp5` places and routes, and with which placement seed.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ecp5Choice {
    /// Names of `flow::ecp5::MODULES`, in that order.
    pub modules: Vec<String>,
    pub seed: u64,
}

/// The swept parameters, in the order configurations vary them (last fastest).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Axis {
    N,
    M,
    EdgeShift,
    T,
    C,
}

impl Axis {
    pub const ALL: [Axis; 5] = [Axis::N, Axis::M, Axis::EdgeShift, Axis::T, Axis::C];
    /// The option name, as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Axis::N => "n",
            Axis::M => "m",
            Axis::EdgeShift => "edge-shift",
            Axis::T => "t",
            Axis::C => "c",
        }
    }
    /// The symbol the thesis uses.
    pub fn symbol(self) -> &'static str {
        match self {
            Axis::N => "n",
            Axis::M => "m",
            Axis::EdgeShift => "E",
            Axis::T => "T",
            Axis::C => "C",
        }
    }
    /// This parameter of `p`, as text (`auto` for the adaptive edge shift).
    pub fn value(self, p: &Params) -> String {
        match self {
            Axis::N => p.n.to_string(),
            Axis::M => p.m.to_string(),
            Axis::EdgeShift => p.edge_shift.to_string(),
            Axis::T => p.t.to_string(),
            Axis::C => p.c.to_string(),
        }
    }
}

/// More configurations than any sweep should hold in one plan (a shard still plans them all).
pub const MAX_CONFIGURATIONS: usize = 1_000_000;

/// One configuration: a parameter set applied to one scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// Position in the whole sweep (shards keep it).
    pub index: usize,
    pub scene: usize,
    pub params: Params,
}

/// A parameter set of the lists whose values cannot be used together.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Skipped {
    pub params: Params,
    pub reason: String,
}

#[derive(Debug)]
pub struct Plan {
    /// The base set: each parameter at its default if the list holds it, else the list's first.
    pub base: Params,
    pub sets: Vec<Params>,
    pub configs: Vec<Config>,
    pub skipped: Vec<Skipped>,
}

impl SweepSpec {
    /// Whether rows carry yosys's Virtex-5 area (`--synth`, family xc5v).
    pub fn xc5v_synth(&self) -> bool {
        self.synth && self.ecp5.is_none()
    }

    /// The values of `axis` as text, in the order given.
    pub fn values(&self, axis: Axis) -> Vec<String> {
        match axis {
            Axis::N => self.n.iter().map(u32::to_string).collect(),
            Axis::M => self.m.iter().map(u32::to_string).collect(),
            Axis::EdgeShift => self.edge_shift.iter().map(EdgeShift::to_string).collect(),
            Axis::T => self.t.iter().map(u32::to_string).collect(),
            Axis::C => self.c.iter().map(u32::to_string).collect(),
        }
    }

    /// The axes that take more than one value.
    pub fn swept_axes(&self) -> Vec<Axis> {
        Axis::ALL.into_iter().filter(|&a| self.values(a).len() > 1).collect()
    }

    /// The default parameters with the sweep's single-valued ones: leaf size, stack depth
    /// and tree.
    pub fn defaults(&self) -> Params {
        Params { leaf_size: self.leaf_size, stack_depth: self.stack_depth, tree: self.tree, ..Params::default() }
    }

    /// Each parameter at its default if its list holds it, else the list's first value.
    pub fn base(&self) -> Params {
        let d = self.defaults();
        let pick = |list: &[u32], default: u32| if list.contains(&default) { default } else { list[0] };
        Params {
            n: pick(&self.n, d.n),
            m: pick(&self.m, d.m),
            t: pick(&self.t, d.t),
            c: pick(&self.c, d.c),
            edge_shift: if self.edge_shift.contains(&d.edge_shift) { d.edge_shift } else { self.edge_shift[0] },
            ..d
        }
    }

    /// Every parameter set the lists describe, in a fixed order, without repeats (the lists
    /// themselves hold no repeats, so only one-at-a-time can produce one: the base).
    fn parameter_sets(&self) -> Vec<Params> {
        let base = self.base();
        let mut sets: Vec<Params> = Vec::new();
        if self.one_at_a_time {
            sets.push(base);
            let mut push = |p: Params| {
                if p != base {
                    sets.push(p);
                }
            };
            self.n.iter().for_each(|&n| push(Params { n, ..base }));
            self.m.iter().for_each(|&m| push(Params { m, ..base }));
            self.edge_shift.iter().for_each(|&edge_shift| push(Params { edge_shift, ..base }));
            self.t.iter().for_each(|&t| push(Params { t, ..base }));
            self.c.iter().for_each(|&c| push(Params { c, ..base }));
        } else {
            for &n in &self.n {
                for &m in &self.m {
                    for &edge_shift in &self.edge_shift {
                        for &t in &self.t {
                            for &c in &self.c {
                                sets.push(Params { n, m, edge_shift, t, c, ..base });
                            }
                        }
                    }
                }
            }
        }
        sets
    }

    /// How many parameter sets the lists describe.
    fn set_count(&self) -> u128 {
        let lens = [self.n.len(), self.m.len(), self.edge_shift.len(), self.t.len(), self.c.len()];
        if self.one_at_a_time {
            1 + lens.iter().map(|&l| l as u128).sum::<u128>()
        } else {
            lens.iter().map(|&l| l as u128).product()
        }
    }

    /// Expands the lists; fails (before anything runs) if no configuration is valid.
    pub fn plan(&self) -> Result<Plan> {
        if self.scenes.is_empty() {
            return Err(Error::new("sweep", "no scene: name OBJ files or --builtin scenes"));
        }
        for axis in Axis::ALL {
            if self.values(axis).is_empty() {
                return Err(Error::param(axis.name(), "the list is empty"));
            }
        }
        let configurations = self.set_count() * self.scenes.len() as u128;
        if configurations > MAX_CONFIGURATIONS as u128 {
            return Err(Error::new(
                "sweep",
                format!(
                    "{configurations} configurations is more than {MAX_CONFIGURATIONS}: shorten the lists or use \
                     --one-at-a-time"
                ),
            ));
        }
        let (mut sets, mut skipped) = (Vec::new(), Vec::new());
        for p in self.parameter_sets() {
            match p.validate() {
                Ok(()) => sets.push(p),
                Err(e) => skipped.push(Skipped { params: p, reason: e.to_string() }),
            }
        }
        if sets.is_empty() {
            let why = skipped.first().map(|s| s.reason.clone()).unwrap_or_default();
            return Err(Error::new("sweep", format!("no valid parameter set in the lists (e.g. {why})")));
        }
        // The base set anchors one-at-a-time sweeps, grids and plots: it must be valid.
        let mut base = self.base();
        if let Err(e) = base.validate() {
            if self.one_at_a_time {
                return Err(Error::new(
                    "sweep",
                    format!("the base set of --one-at-a-time is invalid ({e}): list a valid value first"),
                ));
            }
            base = sets[0];
        }
        let configs = sets
            .iter()
            .enumerate()
            .flat_map(|(i, &params)| {
                (0..self.scenes.len()).map(move |s| Config { index: i * self.scenes.len() + s, scene: s, params })
            })
            .collect();
        Ok(Plan { base, sets, configs, skipped })
    }
}

/// `--shard I/N`: this run computes the configurations with index mod N = I − 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

impl Shard {
    pub fn parse(s: &str) -> std::result::Result<Shard, String> {
        let (i, n) = s.split_once('/').ok_or_else(|| format!("'{s}' is not I/N"))?;
        let i: u32 = i.trim().parse().map_err(|_| format!("'{i}' is not a positive integer"))?;
        let n: u32 = n.trim().parse().map_err(|_| format!("'{n}' is not a positive integer"))?;
        if n == 0 || i == 0 || i > n {
            return Err(format!("{i}/{n} is out of range: need 1 ≤ I ≤ N"));
        }
        Ok(Shard { index: i, count: n })
    }
    pub fn takes(&self, config_index: usize) -> bool {
        config_index % self.count as usize == (self.index - 1) as usize
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// A short label of a parameter set, used in file names: `n29_m32_eauto_t0_c16`.
pub fn params_label(p: &Params) -> String {
    let d = Params::default();
    let mut s = format!("n{}_m{}_e{}_t{}_c{}", p.n, p.m, p.edge_shift, p.t, p.c);
    if p.leaf_size != d.leaf_size {
        s += &format!("_l{}", p.leaf_size);
    }
    if p.stack_depth != d.stack_depth {
        s += &format!("_s{}", p.stack_depth);
    }
    if p.tree != d.tree {
        s += &format!("_{}", p.tree);
    }
    s
}

#[cfg(test)]
mod tests;
