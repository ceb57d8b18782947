//! The hard blocks `fxrt synth --family ecp5` gives a module, counted from the netlist alone
//! (no yosys): DP16KD block RAMs and MULT18X18D multipliers, and the bits left in LUT RAM —
//! what a shape needs of a device before anything is placed (issue 30's `--device`).
//!
//! The counts follow the flow's own rules (`write_sources`): every split multiplier's piece
//! (`fxrt_dsp18_r…`) is one MULT18X18D; a block ROM (`fxrt_brom_…`) of at least `MIN_WORDS`
//! words is the DP16KD banks of `bram::banks`, a smaller one LUTs; a block RAM module
//! (`fxrt_bram_…`) is `width / w` blocks side by side in the widest configuration holding its
//! depth. A RAM left to yosys is LUT RAM up to `DISTRIBUTED_WORDS` words (the printers ask for
//! it), else blocks as for a block RAM module (yosys's `memory_libmap` picks the same
//! configuration for a single read port; its soft read-first logic costs LUTs, not blocks).

use super::bram::{MIN_WORDS, banks, config};
use super::dsp::DSP_MODULE_PREFIX;
use crate::cores::brom::{BRAM_PREFIX, BROM_PREFIX};
use crate::cores::mul::DSP48_MODULE_PREFIX;
use crate::rtl::emit::verilog::DISTRIBUTED_WORDS;
use crate::rtl::netlist::{Def, Module, Rom};
use crate::scene::rom::rom_depth;

/// Hard blocks and LUT-RAM bits of a module and everything it instantiates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Blocks {
    pub dp16kd: usize,
    pub mult18: usize,
    /// Bits of the RAMs and ROMs kept in LUTs (each at its power-of-two depth).
    pub lut_ram_bits: u64,
    /// Register bits left in the fabric: every register, shift register and read register
    /// but those inside the hard blocks (a DSP piece's, a block memory's read and output
    /// registers). Synthesis removes what is constant or unread from these.
    pub fabric_register_bits: u64,
}

impl std::ops::AddAssign for Blocks {
    fn add_assign(&mut self, o: Blocks) {
        self.dp16kd += o.dp16kd;
        self.mult18 += o.mult18;
        self.lut_ram_bits += o.lut_ram_bits;
        self.fabric_register_bits += o.fabric_register_bits;
    }
}

/// DP16KDs for `words` × `width` in the widest configuration holding the depth, or None when
/// deeper than 16K (then yosys would cascade; no fxrt memory is that deep).
fn side_by_side(words: usize, width: u32) -> Option<usize> {
    config(rom_depth(words)).map(|(w, _)| width.div_ceil(w) as usize)
}

fn lut_bits(r: &Rom) -> u64 {
    rom_depth(r.words.len()) as u64 * r.width as u64
}

/// A memory of a module that is neither a block ROM nor a block RAM module: what yosys does.
fn inferred(r: &Rom) -> Blocks {
    match inferred_dp16kd(r) {
        Some(dp16kd) => Blocks { dp16kd, ..Blocks::default() },
        None => Blocks { lut_ram_bits: lut_bits(r), ..Blocks::default() },
    }
}

/// The DP16KDs yosys maps such a memory to, or `None` when it keeps it in LUTs (LUT RAM for a
/// RAM, logic for a ROM): a RAM over `DISTRIBUTED_WORDS` words or a ROM of `MIN_WORDS` or more
/// that the blocks can hold side by side.
pub(super) fn inferred_dp16kd(r: &Rom) -> Option<usize> {
    let deep = if r.write.is_some() { r.words.len() > DISTRIBUTED_WORDS } else { r.words.len() >= MIN_WORDS };
    deep.then(|| side_by_side(r.words.len(), r.width)).flatten()
}

/// Register bits of the module itself: registers, shift registers and, with `reads`, the read
/// registers of its memories.
fn register_bits(m: &Module, reads: bool) -> u64 {
    m.signals
        .iter()
        .map(|s| match s.def {
            Def::Reg { .. } => s.ty.width as u64,
            Def::DelayLine { depth, .. } => s.ty.width as u64 * depth as u64,
            Def::RomRead { .. } if reads => s.ty.width as u64,
            _ => 0,
        })
        .sum()
}

/// Whether `m` is a block ROM or block RAM module the flow maps to DP16KDs (its one memory
/// deep enough).
pub(super) fn is_block_module(m: &Module) -> bool {
    m.roms.len() == 1
        && m.roms[0].words.len() >= MIN_WORDS
        && (m.name.starts_with(BROM_PREFIX)
            || (m.name.starts_with(BRAM_PREFIX) && side_by_side(m.roms[0].words.len(), m.roms[0].width).is_some()))
}

/// The module's own memories and multiplier pieces, without its instances.
fn own(m: &Module) -> Blocks {
    if m.name.starts_with(DSP_MODULE_PREFIX) {
        return Blocks { mult18: 1, ..Blocks::default() };
    }
    // A DSP48E-sized piece (a core cut for the Xilinx parts, DECISIONS 131) would be two.
    if m.name.starts_with(DSP48_MODULE_PREFIX) {
        return Blocks { mult18: 2, ..Blocks::default() };
    }
    let block_module = is_block_module(m);
    // A block memory module's read register and first register after it are the block's (one
    // per read port: each output).
    let inside = if block_module { m.roms[0].width as u64 * m.outputs.len() as u64 } else { 0 };
    let mut out = Blocks { fabric_register_bits: register_bits(m, !block_module) - inside, ..Blocks::default() };
    for r in &m.roms {
        let big = r.words.len() >= MIN_WORDS;
        out += if m.name.starts_with(BROM_PREFIX) && big {
            let dp16kd = banks(r.words.len(), r.width).iter().map(|b| b.blocks(r.width)).sum();
            let tail: u64 = banks(r.words.len(), r.width)
                .iter()
                .filter(|b| b.w == 0)
                .map(|b| (1u64 << b.abits) * r.width as u64)
                .sum();
            Blocks { dp16kd, lut_ram_bits: tail, ..Blocks::default() }
        } else if m.name.starts_with(BRAM_PREFIX) && big && side_by_side(r.words.len(), r.width).is_some() {
            Blocks { dp16kd: side_by_side(r.words.len(), r.width).unwrap_or(0), ..Blocks::default() }
        } else {
            inferred(r)
        };
    }
    out
}

/// The hard blocks of `m` with every instance below it (an instantiated module counts once per
/// instance).
pub fn blocks(m: &Module) -> Blocks {
    let mut out = own(m);
    for inst in &m.instances {
        out += blocks(&inst.module);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cores::core_params::{CoreParams, CoreSpec};
    use crate::cores::memory_params::MemorySpec;
    use crate::cores::top::core_module_with;
    use crate::params::Params;
    use crate::scene::Scene;
    use crate::scene::builtin::builtin_scene;
    use crate::scene::images::SceneRoms;

    fn roms(name: &str, params: &Params) -> SceneRoms {
        SceneRoms::of(&Scene::build(name, builtin_scene(name).unwrap(), params).unwrap())
    }

    /// The counts nextpnr placed (docs/TIMING.md, docs/MEMORY.md, docs/BOARDS.md): the default
    /// core on the teapot, 170 DP16KD and 70 MULT18X18D; the throughput build (4 × 32 slots,
    /// leaves ≤ 3) 204 and 94; the Cornell box's core of one unit × 8 slots 4 and 58; four
    /// units × 32 slots with two intersection pipelines (their ROMs on two ports) 196 and 134,
    /// and since DECISIONS 137 its two pair ROMs 12 DP16KD more (counted by the same rule as
    /// the node ROMs; not placed yet).
    #[test]
    fn on_chip_cores_count_what_nextpnr_placed() {
        let leaf3 = Params { leaf_size: 3, ..Params::default() };
        for (scene, params, [slots, units, pipelines], dp16kd, mult18) in [
            ("teapot", Params::default(), [64, 2, 1], 170, 70),
            ("teapot", leaf3, [32, 4, 1], 204, 94),
            ("cornell", Params::default(), [8, 1, 1], 4, 58),
            ("teapot", Params::default(), [32, 4, 2], 208, 134),
        ] {
            let r = roms(scene, &params);
            let p = CoreParams::shaped(&r, &CoreSpec { slots, units, pipelines, ..CoreSpec::default() });
            let got = blocks(&core_module_with(&p, &r, false));
            assert_eq!((got.dp16kd, got.mult18), (dp16kd, mult18), "{scene} {units} × {slots}: {got:?}");
        }
    }

    /// The teapot-fine core with its scene in external memory behind 2 × 64 KB node caches and
    /// a 128 KB triangle cache: 150 DP16KD and 70 MULT18X18D placed (docs/MEMORY.md).
    #[test]
    fn the_external_core_counts_what_nextpnr_placed() {
        let r = roms("teapot-fine", &Params::default());
        let spec = MemorySpec { node_cache_kb: 64, tri_cache_kb: 128, ..MemorySpec::default() };
        let p = CoreParams::external(&r, &CoreSpec::default(), spec).unwrap();
        let got = blocks(&core_module_with(&p, &r, false));
        assert_eq!((got.dp16kd, got.mult18), (150, 70), "{got:?}");
    }
}
