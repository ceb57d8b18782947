//! The shape of a core that reads its scene from external memory (`--memory external`,
//! docs/MEMORY.md): the options (`MemorySpec`) and what the core's parts derive from them for
//! a scene (`ExternalMemory`: the image layout, the node and triangle caches, the read master),
//! with the checks that name the option to change.

use super::axi_read::AxiReadParams;
use super::cache::CacheParams;
use crate::bits::addr_bits;
use crate::error::{Error, Result};
use crate::scene::images::SceneRoms;
use crate::scene::memory::{MemoryLayout, MemoryShape};

/// The defaults of `--node-cache-kb` (each traversal unit's), `--tri-cache-kb`,
/// `--cache-ways`, `--mem-addr-bits` (docs/MEMORY.md: the sizes the trace model chose).
pub const DEFAULT_NODE_CACHE_KB: u32 = 32;
pub const DEFAULT_TRI_CACHE_KB: u32 = 64;
pub const DEFAULT_WAYS: u32 = 2;
pub const DEFAULT_ADDR_BITS: u32 = 32;
/// Lines each cache may have in flight (its table is searched on every miss).
pub const INFLIGHT: u32 = 8;
/// Bursts the read master keeps in flight at most.
pub const OUTSTANDING: u32 = 16;

/// `--cache-ways`: 1, 2 or 4.
pub fn check_ways(ways: u32) -> Result<()> {
    if ![1, 2, 4].contains(&ways) {
        return Err(Error::param("cache-ways", format!("{ways} is not one of 1, 2, 4")));
    }
    Ok(())
}

/// The sets of a `kb`-KB cache of `ways`-way sets of `line`-byte lines: refused (naming
/// `flag`) unless a power of two of at least two, and the size 1 to 4096 KB.
pub fn check_cache_kb(flag: &'static str, kb: u32, line: u32, ways: u32) -> Result<u64> {
    let sets = (kb as u64 * 1024) / line as u64 / ways as u64;
    if kb == 0 || kb > 4096 || !sets.is_power_of_two() || sets < 2 {
        return Err(Error::param(
            flag,
            format!(
                "{kb} KB: a cache must hold a power of two of at least two sets of {ways} {line}-byte lines (e.g. {} \
                 KB)",
                (2 * ways * line).div_ceil(1024).next_power_of_two()
            ),
        ));
    }
    Ok(sets)
}

/// The options of an external-memory core.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemorySpec {
    pub shape: MemoryShape,
    pub node_cache_kb: u32,
    pub tri_cache_kb: u32,
    pub ways: u32,
    /// Bits of ARADDR (and of the base-address input).
    pub addr_bits: u32,
}

impl Default for MemorySpec {
    fn default() -> MemorySpec {
        MemorySpec {
            shape: MemoryShape::default(),
            node_cache_kb: DEFAULT_NODE_CACHE_KB,
            tri_cache_kb: DEFAULT_TRI_CACHE_KB,
            ways: DEFAULT_WAYS,
            addr_bits: DEFAULT_ADDR_BITS,
        }
    }
}

/// What the core's memory side is for one scene.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExternalMemory {
    pub spec: MemorySpec,
    pub layout: MemoryLayout,
    /// Each traversal unit's node cache, and the triangle cache.
    pub node: CacheParams,
    pub tri: CacheParams,
    pub axi: AxiReadParams,
    /// Bits of a record's place in its leaf: the staging RAM holds 2^stage_bits records per slot.
    pub stage_bits: u32,
}

impl ExternalMemory {
    pub fn new(roms: &SceneRoms, spec: MemorySpec) -> Result<ExternalMemory> {
        let layout = MemoryLayout::for_roms(roms, spec.shape)?;
        check_ways(spec.ways)?;
        if !(12..=64).contains(&spec.addr_bits) || layout.total_bytes > 1u64 << spec.addr_bits.min(63) {
            return Err(Error::param(
                "mem-addr-bits",
                format!(
                    "{}: the scene image takes {} bytes; the address must be 12 to 64 bits and hold it",
                    spec.addr_bits, layout.total_bytes
                ),
            ));
        }
        if layout.node.width > crate::rtl::width::MAX_WIDTH {
            return Err(Error::param(
                "n",
                format!(
                    "a node record of {} bits is wider than the RTL layer's signals: a smaller n",
                    layout.node.width
                ),
            ));
        }
        let (line, beat) = (spec.shape.line_bytes, spec.shape.beat_bytes());
        let cache = |flag: &'static str, kb: u32, rec_bytes: u32, records_per_line: u32, lines: u64, bits: u32| {
            let sets = check_cache_kb(flag, kb, line, spec.ways)?;
            Ok(CacheParams {
                record_bits: bits,
                record_beats: rec_bytes / beat,
                records_per_line,
                line_beats: line / beat,
                data_bits: spec.shape.mem_bits,
                sets: sets as u32,
                ways: spec.ways,
                // At least the set bits: a scene smaller than the cache still indexes every set.
                line_bits: addr_bits(lines as usize).max(sets.trailing_zeros()),
                inflight: INFLIGHT,
            })
        };
        let node_lines = (layout.node_records * layout.node_bytes as u64).div_ceil(line as u64);
        let node = cache(
            "node-cache-kb",
            spec.node_cache_kb,
            layout.node_bytes,
            line / layout.node_bytes,
            node_lines,
            layout.node.width,
        )?;
        let tri = cache(
            "tri-cache-kb",
            spec.tri_cache_kb,
            layout.tri_bytes,
            layout.tris_per_line,
            layout.tri_lines,
            layout.tri.width,
        )?;
        let axi = AxiReadParams {
            addr_bits: spec.addr_bits,
            data_bits: spec.shape.mem_bits,
            line_beats: line / beat,
            outstanding: OUTSTANDING,
            queue: INFLIGHT,
        };
        let count = roms.node.0.field("count");
        let largest = roms.node.1.iter().filter(|w| w.get(roms.node.0.field("axis")) == 3).map(|w| w.get(count));
        let largest = largest.max().unwrap_or(1).max(1) as usize;
        // A leaf may span more lines than the triangle cache has sets: a pass over it keeps
        // what it staged and looks up only the rest, and a line stays until its first hit
        // (DECISIONS 109), so its lines evicting one another cannot stall it for ever.
        Ok(ExternalMemory { spec, layout, node, tri, axi, stage_bits: addr_bits(largest) })
    }

    /// Bits of block RAM the memory side takes: `units` node caches, the triangle cache and the
    /// staging RAM (`slots` global slots).
    pub fn bram_bits(&self, units: u32, slots: u32) -> u64 {
        let staging = ((slots as u64) << self.stage_bits) * self.tri.record_bits as u64;
        units as u64 * self.node.bits() + self.tri.bits() + staging
    }

    /// Rejects caches, staging RAM and `stack_bits` of stacks that do not fit `bram_kbits`.
    pub fn check_device(&self, units: u32, slots: u32, stack_bits: u64, bram_kbits: u64) -> Result<()> {
        let total = self.bram_bits(units, slots) + stack_bits;
        if total > bram_kbits * 1024 {
            return Err(Error::param(
                "bram-kbits",
                format!(
                    "the caches ({units} × {} KB of nodes, {} KB of triangles), the staging RAM and the stacks need {} Kb, \
                     more than the {bram_kbits} Kb of block RAM allowed: smaller --node-cache-kb/--tri-cache-kb, \
                     fewer --slots/--units, or a larger --bram-kbits",
                    self.spec.node_cache_kb,
                    self.spec.tri_cache_kb,
                    total.div_ceil(1024)
                ),
            ));
        }
        Ok(())
    }

    /// Byte offsets of the node and triangle regions in the image (each cache's lines are
    /// numbered from its region's start).
    pub fn regions(&self) -> (u64, u64) {
        (self.layout.node_offset, self.layout.tri_offset)
    }

    /// Records of a node cache line, as a shift: node record k is record k mod 2^s of line k >> s.
    pub fn node_line_shift(&self) -> u32 {
        (self.spec.shape.line_bytes / self.layout.node_bytes).trailing_zeros()
    }
}
