//! `fxrt sweep`: image error, hardware cost and throughput over lists of n, m, T, C, E, the
//! BIH's leaf size and the core's ray slots K and traversal units U, for one or more scenes
//! (seed 001 figures 2.7–2.9, seed 003's edge shift).
//!
//! A sweep is a `SweepSpec` (what the user asked for, independent of where it runs), expanded
//! into a `Plan` (configurations numbered 0..N, and the parameter sets that are invalid
//! together). Each configuration is evaluated once and cached by its key; a shard evaluates
//! the configurations with index ≡ I−1 (mod N); `merge` joins shards. The outputs are a
//! function of (spec, rows) alone, so a merged sweep is byte-identical to an unsharded one.

pub mod compat;
pub mod draw;
pub mod eval;
pub mod fit;
pub mod grid;
pub mod memory;
pub mod output;
pub mod plots;
pub mod pnr;
pub mod report;
pub mod run;
pub mod slurm;
pub mod summary;
pub mod throughput;
pub mod values;

use crate::cores::top::{DEFAULT_SLOTS, DEFAULT_UNITS};
use crate::error::{Error, Result};
pub use crate::model::camera::CameraSpec;
use crate::params::{EdgeShift, Params, TreeSplit};
use crate::scene::SceneSource;
use compat::{
    default_slots, default_units, is_default_slots, is_default_units, is_one_pipeline, one_or_many, one_pipeline,
};
use memory::{MemoryPoint, MemorySweep};
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
    /// Largest triangles per BIH leaf (`--leaf-size`; one value is written as a number, as
    /// before it became a list, and a number reads back as a list of one).
    #[serde(with = "one_or_many")]
    pub leaf_size: Vec<u32>,
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
    /// Ray slots per traversal unit and traversal units of the cores (`--slots`, `--units`;
    /// absent from results.json at the defaults, so older sweeps read back the same; one
    /// value is written as a number, as before they became lists).
    #[serde(default = "default_slots", skip_serializing_if = "is_default_slots", with = "one_or_many")]
    pub slots: Vec<u32>,
    #[serde(default = "default_units", skip_serializing_if = "is_default_units", with = "one_or_many")]
    pub units: Vec<u32>,
    /// Intersection pipelines of every core: one, or what `--device` fitted (absent when one).
    #[serde(default = "one_pipeline", skip_serializing_if = "is_one_pipeline")]
    pub pipelines: u32,
    /// `--device`: the fit that chose the slots, units and pipelines (`sweep::fit::Fit::json`),
    /// made on the first scene at the base set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device_fit: Option<serde_json::Value>,
    /// `--synth --family ecp5`: place and route on the LFE5U-85F instead of Virtex-5 area.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ecp5: Option<Ecp5Choice>,
    /// `--memory external`: the cores read their scene from external memory; the memory's
    /// latency and the caches' sizes are axes (absent for on-chip sweeps, as before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub memory: Option<MemorySweep>,
}

fn default_target_mhz() -> u32 {
    crate::cores::clock::DEFAULT_TARGET_MHZ
}

fn is_default_target_mhz(mhz: &u32) -> bool {
    *mhz == default_target_mhz()
}

impl SweepSpec {
    /// Whether every core has the default ray slots and units (`--slots`, `--units` not given).
    pub fn default_core_shape(&self) -> bool {
        is_default_slots(&self.slots) && is_default_units(&self.units) && self.pipelines == 1
    }

    /// The device `--device` fitted the cores to.
    pub fn fitted_device(&self) -> Option<crate::fpga::device::Device> {
        self.device_fit.as_ref().and_then(|f| serde_json::from_value(f["device"].clone()).ok())
    }
}

/// What `sweep --synth --family ecp5` places and routes, and with which placement seed.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ecp5Choice {
    /// Names of `fpga::ecp5::MODULES`, in that order.
    pub modules: Vec<String>,
    pub seed: u64,
}

/// The swept parameters, in the order configurations vary them (last fastest): the
/// arithmetic's, the BIH's leaf size, and the core's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Axis {
    N,
    M,
    EdgeShift,
    T,
    C,
    LeafSize,
    Slots,
    Units,
    MemLatency,
    NodeCacheKb,
    TriCacheKb,
}

impl Axis {
    pub const ALL: [Axis; 11] = [
        Axis::N,
        Axis::M,
        Axis::EdgeShift,
        Axis::T,
        Axis::C,
        Axis::LeafSize,
        Axis::Slots,
        Axis::Units,
        Axis::MemLatency,
        Axis::NodeCacheKb,
        Axis::TriCacheKb,
    ];
    /// The axes of an external-memory sweep (`--memory external`).
    pub const MEMORY: [Axis; 3] = [Axis::MemLatency, Axis::NodeCacheKb, Axis::TriCacheKb];
    /// The axes sweeps had before the leaf size and the core's shape became lists: always
    /// named in titles and labels; the others only when swept.
    pub const ARITHMETIC: [Axis; 5] = [Axis::N, Axis::M, Axis::EdgeShift, Axis::T, Axis::C];
    /// The option name, as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Axis::N => "n",
            Axis::M => "m",
            Axis::EdgeShift => "edge-shift",
            Axis::T => "t",
            Axis::C => "c",
            Axis::LeafSize => "leaf-size",
            Axis::Slots => "slots",
            Axis::Units => "units",
            Axis::MemLatency => "mem-latency",
            Axis::NodeCacheKb => "node-cache-kb",
            Axis::TriCacheKb => "tri-cache-kb",
        }
    }
    /// The symbol the thesis uses (docs/CORE.md's K and U for the core's shape).
    pub fn symbol(self) -> &'static str {
        match self {
            Axis::N => "n",
            Axis::M => "m",
            Axis::EdgeShift => "E",
            Axis::T => "T",
            Axis::C => "C",
            Axis::LeafSize => "leaf",
            Axis::Slots => "K",
            Axis::Units => "U",
            Axis::MemLatency => "L",
            Axis::NodeCacheKb => "node KB",
            Axis::TriCacheKb => "tri KB",
        }
    }
    /// This parameter of `s`, as text (`auto` for the adaptive edge shift).
    pub fn value(self, s: &Set) -> String {
        let p = &s.params;
        match self {
            Axis::N => p.n.to_string(),
            Axis::M => p.m.to_string(),
            Axis::EdgeShift => p.edge_shift.to_string(),
            Axis::T => p.t.to_string(),
            Axis::C => p.c.to_string(),
            Axis::LeafSize => p.leaf_size.to_string(),
            Axis::Slots => s.shape.slots.to_string(),
            Axis::Units => s.shape.units.to_string(),
            Axis::MemLatency => s.shape.memory.latency.to_string(),
            Axis::NodeCacheKb => s.shape.memory.node_cache_kb.to_string(),
            Axis::TriCacheKb => s.shape.memory.tri_cache_kb.to_string(),
        }
    }
    /// Whether the golden model's image can depend on this parameter (the core's shape and
    /// its memory change how fast the core computes it, not what).
    pub fn changes_image(self) -> bool {
        !matches!(self, Axis::Slots | Axis::Units) && !Axis::MEMORY.contains(&self)
    }
}

/// More configurations than any sweep should hold in one plan (a shard still plans them all).
pub const MAX_CONFIGURATIONS: usize = 1_000_000;

/// The core's shape: ray slots per traversal unit (K) and traversal units (U), docs/CORE.md;
/// with `--memory external` also its caches' sizes and the memory's latency (docs/MEMORY.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct CoreShape {
    pub slots: u32,
    pub units: u32,
    /// Absent from rows with one (every sweep before `--device`).
    #[serde(default = "one_pipeline", skip_serializing_if = "is_one_pipeline")]
    pub pipelines: u32,
    /// Absent from rows at the defaults (every on-chip sweep), as before it was swept.
    #[serde(default, skip_serializing_if = "MemoryPoint::is_default")]
    pub memory: MemoryPoint,
}

impl Default for CoreShape {
    fn default() -> Self {
        CoreShape { slots: DEFAULT_SLOTS, units: DEFAULT_UNITS, pipelines: 1, memory: MemoryPoint::default() }
    }
}

impl CoreShape {
    pub fn is_default(&self) -> bool {
        *self == CoreShape::default()
    }
}

impl std::fmt::Display for CoreShape {
    /// `K×U`, e.g. `64×2`; `K×U×P` with P > 1 pipelines.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}×{}", self.slots, self.units)?;
        if self.pipelines > 1 { write!(f, "×{}", self.pipelines) } else { Ok(()) }
    }
}

/// A point of the sweep: the model's parameters and the core's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Set {
    pub params: Params,
    pub shape: CoreShape,
}

/// One configuration: a set applied to one scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// Position in the whole sweep (shards keep it).
    pub index: usize,
    pub scene: usize,
    pub params: Params,
    pub shape: CoreShape,
}

/// A parameter set of the lists whose values cannot be used together (the core's shape is
/// checked when the lists are read, so it never makes a set invalid).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Skipped {
    pub params: Params,
    pub reason: String,
}

#[derive(Debug)]
pub struct Plan {
    /// The base set: each parameter at its default if the list holds it, else the list's first.
    pub base: Set,
    pub sets: Vec<Set>,
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
        let text = |v: &[u32]| v.iter().map(u32::to_string).collect();
        match axis {
            Axis::N => text(&self.n),
            Axis::M => text(&self.m),
            Axis::EdgeShift => self.edge_shift.iter().map(EdgeShift::to_string).collect(),
            Axis::T => text(&self.t),
            Axis::C => text(&self.c),
            Axis::LeafSize => text(&self.leaf_size),
            Axis::Slots => text(&self.slots),
            Axis::Units => text(&self.units),
            Axis::MemLatency | Axis::NodeCacheKb | Axis::TriCacheKb => text(&self.memory_values(axis)),
        }
    }

    /// The values of a memory axis: its list with `--memory external`, else its default.
    fn memory_values(&self, axis: Axis) -> Vec<u32> {
        let d = MemoryPoint::default();
        match (&self.memory, axis) {
            (Some(m), Axis::MemLatency) => m.latency.clone(),
            (Some(m), Axis::NodeCacheKb) => m.node_cache_kb.clone(),
            (Some(m), _) => m.tri_cache_kb.clone(),
            (None, Axis::MemLatency) => vec![d.latency],
            (None, Axis::NodeCacheKb) => vec![d.node_cache_kb],
            (None, _) => vec![d.tri_cache_kb],
        }
    }

    /// How many values `axis` takes.
    fn len(&self, axis: Axis) -> usize {
        self.values(axis).len()
    }

    /// `s` with `axis` at its `i`-th listed value.
    fn with(&self, mut s: Set, axis: Axis, i: usize) -> Set {
        let p = &mut s.params;
        match axis {
            Axis::N => p.n = self.n[i],
            Axis::M => p.m = self.m[i],
            Axis::EdgeShift => p.edge_shift = self.edge_shift[i],
            Axis::T => p.t = self.t[i],
            Axis::C => p.c = self.c[i],
            Axis::LeafSize => p.leaf_size = self.leaf_size[i],
            Axis::Slots => s.shape.slots = self.slots[i],
            Axis::Units => s.shape.units = self.units[i],
            Axis::MemLatency => s.shape.memory.latency = self.memory_values(axis)[i],
            Axis::NodeCacheKb => s.shape.memory.node_cache_kb = self.memory_values(axis)[i],
            Axis::TriCacheKb => s.shape.memory.tri_cache_kb = self.memory_values(axis)[i],
        }
        s
    }

    /// The axes that take more than one value.
    pub fn swept_axes(&self) -> Vec<Axis> {
        Axis::ALL.into_iter().filter(|&a| self.len(a) > 1).collect()
    }

    /// The axes titles and labels name: n, m, E, T, C always, the others when swept.
    pub fn named_axes(&self) -> Vec<Axis> {
        Axis::ALL.into_iter().filter(|&a| Axis::ARITHMETIC.contains(&a) || self.len(a) > 1).collect()
    }

    /// A set as text: `n=29 m=32 E=auto T=0 C=16`, then leaf, K and U where they are swept.
    pub fn set_text(&self, s: &Set) -> String {
        self.named_axes().into_iter().map(|a| format!("{}={}", a.symbol(), a.value(s))).collect::<Vec<_>>().join(" ")
    }

    /// Parameters as text, without the core's shape (for what the shape does not change,
    /// such as a parameter set that is invalid).
    pub fn params_text(&self, p: &Params) -> String {
        let s = Set { params: *p, shape: CoreShape::default() };
        let axes = self.named_axes().into_iter().filter(|a| a.changes_image());
        axes.map(|a| format!("{}={}", a.symbol(), a.value(&s))).collect::<Vec<_>>().join(" ")
    }

    /// The default parameters with the sweep's single-valued ones (stack depth and tree) and
    /// the base leaf size.
    pub fn defaults(&self) -> Params {
        let d = Params::default();
        let leaf_size = if self.leaf_size.contains(&d.leaf_size) { d.leaf_size } else { self.leaf_size[0] };
        Params { leaf_size, stack_depth: self.stack_depth, tree: self.tree, ..d }
    }

    /// Each parameter at its default if its list holds it, else the list's first value.
    pub fn base(&self) -> Set {
        let d = Set { params: self.defaults(), shape: CoreShape { pipelines: self.pipelines, ..CoreShape::default() } };
        Axis::ALL.into_iter().fold(d, |s, a| {
            let here = a.value(&d);
            let i = self.values(a).iter().position(|v| *v == here).unwrap_or(0);
            self.with(s, a, i)
        })
    }

    /// Every set the lists describe, in a fixed order, without repeats (the lists themselves
    /// hold no repeats, so only one-at-a-time can produce one: the base).
    fn sets(&self) -> Vec<Set> {
        let base = self.base();
        let mut sets: Vec<Set> = vec![base];
        if self.one_at_a_time {
            for a in Axis::ALL {
                sets.extend((0..self.len(a)).map(|i| self.with(base, a, i)).filter(|s| *s != base));
            }
        } else {
            // The cross product, the last axis fastest.
            for a in Axis::ALL {
                sets = sets
                    .iter()
                    .flat_map(|&s| (0..self.len(a)).map(move |i| (s, i)))
                    .map(|(s, i)| self.with(s, a, i))
                    .collect();
            }
        }
        sets
    }

    /// How many sets the lists describe.
    fn set_count(&self) -> u128 {
        let lens = Axis::ALL.map(|a| self.len(a) as u128);
        if self.one_at_a_time { 1 + lens.iter().sum::<u128>() } else { lens.iter().product() }
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
        let (mut sets, mut skipped) = (Vec::new(), Vec::<Skipped>::new());
        for s in self.sets() {
            match s.params.validate() {
                Ok(()) => sets.push(s),
                // A parameter set is listed once, however many core shapes it comes with.
                Err(_) if skipped.iter().any(|k| k.params == s.params) => {}
                Err(e) => skipped.push(Skipped { params: s.params, reason: e.to_string() }),
            }
        }
        if sets.is_empty() {
            let why = skipped.first().map(|s| s.reason.clone()).unwrap_or_default();
            return Err(Error::new("sweep", format!("no valid parameter set in the lists (e.g. {why})")));
        }
        // The base set anchors one-at-a-time sweeps, grids and plots: it must be valid.
        let mut base = self.base();
        if let Err(e) = base.params.validate() {
            if self.one_at_a_time {
                return Err(Error::new(
                    "sweep",
                    format!("the base set of --one-at-a-time is invalid ({e}): list a valid value first"),
                ));
            }
            base = sets[0];
        }
        let scenes = self.scenes.len();
        let configs = sets
            .iter()
            .enumerate()
            .flat_map(|(i, s)| {
                (0..scenes).map(move |k| Config { index: i * scenes + k, scene: k, params: s.params, shape: s.shape })
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

/// Labels for the scenes: built-in names and OBJ file stems, numbered where two coincide
/// (and numbered further while a number collides with another scene's name).
pub fn scene_labels(scenes: &[SceneSpec]) -> Vec<String> {
    let base: Vec<String> = scenes
        .iter()
        .map(|s| match s {
            SceneSpec::Builtin(b) => b.clone(),
            SceneSpec::Obj(p) => p.file_stem().map(|x| x.to_string_lossy().into_owned()).unwrap_or("scene".into()),
        })
        .map(|l| l.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect())
        .collect();
    let mut out: Vec<String> = Vec::new();
    for (i, l) in base.iter().enumerate() {
        let shared = base.iter().filter(|x| *x == l).count() > 1;
        let mut k = 1 + base[..i].iter().filter(|x| *x == l).count();
        let mut label = if shared { format!("{l}-{k}") } else { l.clone() };
        while out.contains(&label) || (shared && base.contains(&label)) {
            k += 1;
            label = format!("{l}-{k}");
        }
        out.push(label);
    }
    out
}

/// `params_label` with the core's shape when it is not the default: `…_c16_k8_u1`, and the
/// memory point when not the default: `…_lat100_nc32_tc64`.
pub fn set_label(s: &Set) -> String {
    let mut label = params_label(&s.params);
    let m = s.shape.memory;
    if (s.shape.slots, s.shape.units) != (DEFAULT_SLOTS, DEFAULT_UNITS) {
        label += &format!("_k{}_u{}", s.shape.slots, s.shape.units);
    }
    if s.shape.pipelines > 1 {
        label += &format!("_p{}", s.shape.pipelines);
    }
    if !m.is_default() {
        label += &format!("_lat{}_nc{}_tc{}", m.latency, m.node_cache_kb, m.tri_cache_kb);
    }
    label
}

#[cfg(test)]
mod tests;
