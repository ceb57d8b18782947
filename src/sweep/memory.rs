//! `sweep --memory external`: every configuration's core reads its scene from external memory
//! (docs/MEMORY.md), with the memory's latency and the node and triangle caches' sizes as axes;
//! with `--core-sim` each row gains what the memory side did (`fxrt sim`'s figures) and
//! results.csv the columns `MEMORY_COLUMNS`.

use super::SweepSpec;
use crate::cores::memory_params::{DEFAULT_NODE_CACHE_KB, DEFAULT_TRI_CACHE_KB, MemorySpec};
use crate::scene::memory::MemoryShape;
use crate::verify::frame_memory::MemoryFigures;
use crate::verify::memory::{DEFAULT_LATENCY, MemoryTiming};
use serde::{Deserialize, Serialize};

/// What an external-memory sweep holds fixed (the lists are `SweepSpec`'s axes).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct MemorySweep {
    /// The read port's data width and the cache line, bytes (`--mem-bits`, `--cache-line`).
    pub mem_bits: u32,
    pub cache_line: u32,
    /// Ways of each cache (`--cache-ways`).
    pub ways: u32,
    /// Rays fed in 8 × 8 tiles instead of pixel order (`--ray-order tiles`).
    pub tiles: bool,
    /// The memory's latency, clocks (`--mem-latency`), each traversal unit's node cache and the
    /// triangle cache, KB (`--node-cache-kb`, `--tri-cache-kb`): the lists swept.
    pub latency: Vec<u32>,
    pub node_cache_kb: Vec<u32>,
    pub tri_cache_kb: Vec<u32>,
}

impl MemorySweep {
    /// The core's memory options at `point`.
    pub fn spec(&self, point: MemoryPoint) -> MemorySpec {
        MemorySpec {
            shape: MemoryShape { mem_bits: self.mem_bits, line_bytes: self.cache_line },
            node_cache_kb: point.node_cache_kb,
            tri_cache_kb: point.tri_cache_kb,
            ways: self.ways,
            ..Default::default()
        }
    }
}

/// The memory model at `point`: its latency, the other timing options at their defaults (no
/// jitter, no pauses), as `fxrt sim` runs by default.
pub fn timing(point: MemoryPoint) -> MemoryTiming {
    MemoryTiming { latency: point.latency, ..Default::default() }
}

/// One point of the memory axes (at the defaults in sweeps without `--memory external`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct MemoryPoint {
    pub latency: u32,
    pub node_cache_kb: u32,
    pub tri_cache_kb: u32,
}

impl Default for MemoryPoint {
    fn default() -> Self {
        MemoryPoint {
            latency: DEFAULT_LATENCY,
            node_cache_kb: DEFAULT_NODE_CACHE_KB,
            tri_cache_kb: DEFAULT_TRI_CACHE_KB,
        }
    }
}

impl MemoryPoint {
    pub fn is_default(&self) -> bool {
        *self == MemoryPoint::default()
    }
}

/// What the memory side did over a configuration's frame (`fxrt sim`'s JSON figures) and the
/// block RAM bits of the node caches, the triangle cache and its staging RAM
/// (`ExternalMemory::bram_bits`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MemoryRun {
    #[serde(flatten)]
    pub figures: MemoryFigures,
    pub cache_bram_bits: u64,
}

/// Columns of an external-memory sweep (before the ECP5 columns): the point, then with
/// `--core-sim` the memory side's figures.
pub const POINT_COLUMNS: [&str; 3] = ["mem_latency", "node_cache_kb", "tri_cache_kb"];
pub const RUN_COLUMNS: [&str; 7] = [
    "mem_bytes_per_ray",
    "mem_reads_per_ray",
    "node_cache_hit_rate",
    "tri_cache_hit_rate",
    "mem_busy",
    "memory_stall_fraction",
    "cache_bram_bits",
];

/// The memory columns `spec` has (none on chip).
pub fn csv_columns(spec: &SweepSpec) -> Vec<String> {
    if spec.memory.is_none() {
        return Vec::new();
    }
    let run = if spec.core_sim { &RUN_COLUMNS[..] } else { &[] };
    POINT_COLUMNS.iter().chain(run).map(|c| c.to_string()).collect()
}

/// A row's cells under `csv_columns`.
pub fn csv_cells(spec: &SweepSpec, point: MemoryPoint, run: Option<&MemoryRun>) -> Vec<String> {
    if spec.memory.is_none() {
        return Vec::new();
    }
    let mut cells = vec![point.latency.to_string(), point.node_cache_kb.to_string(), point.tri_cache_kb.to_string()];
    if spec.core_sim {
        let f = |v: fn(&MemoryFigures) -> f64| run.map(|r| v(&r.figures).to_string()).unwrap_or_default();
        cells.extend([
            f(|r| r.mem_bytes_per_ray),
            f(|r| r.mem_reads_per_ray),
            f(|r| r.node_cache_hit_rate),
            f(|r| r.tri_cache_hit_rate),
            f(|r| r.mem_busy),
            f(|r| r.memory_stall_fraction),
        ]);
        cells.push(run.map(|r| r.cache_bram_bits.to_string()).unwrap_or_default());
    }
    cells
}
