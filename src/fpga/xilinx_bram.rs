//! The block RAMs a module takes on the Xilinx parts (Virtex-5, 7 series), counted from the
//! netlist alone, as yosys's `memory_libmap` maps each memory with `brams_xc4v.txt` (the
//! library `synth_xilinx -family xc5v|xc7` reads): what `--device xc5vlx110t|xc7a100t` fits
//! against, before any synthesis.
//!
//! The rule, from `memory_libmap`'s geometry search: a memory of D words × W bits in a block
//! whose port is w bits wide (and so 2^abits / w words deep, w counted as the w-th of the
//! block's widths 1, 2, 4, 9, 18, 36, 72) needs `a = ⌈D / depth⌉` address regions, and the
//! regions' bits are packed side by side: `⌈a · W / w⌉` blocks. Each read port then picks its
//! word from the a regions in soft logic. The choice is the cheapest of every block and width:
//! 257 per RAMB36 and 129 per RAMB18 (the library's costs), twice that where one block's ports
//! cannot serve all the memory's, plus half a unit per multiplexer input bit. So the teapot's
//! 8,192 × 13-bit leaf ROM is 3 RAMB36 (9-bit ports, two regions packed into 26 bits), its
//! 8,192 × 32-bit triangle ROM part 15 RAMB18. Checked against yosys module by module in
//! `tests/hdl.rs`.
//!
//! Which memories are blocks follows the printers: a RAM of at most `DISTRIBUTED_WORDS` words
//! is asked for in LUTs, a ROM of fewer than `BLOCK_WORDS` words is left to LUTs.

use crate::cores::brom::BLOCK_WORDS;
use crate::rtl::emit::verilog::DISTRIBUTED_WORDS;
use crate::rtl::netlist::{Def, Module, Rom};
use crate::scene::rom::rom_depth;

/// Block RAMs of the Xilinx parts: RAMB36 and RAMB18 (half a RAMB36 site each).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Brams {
    pub ramb36: u32,
    pub ramb18: u32,
}

impl Brams {
    /// RAMB36 sites taken: two RAMB18 share one.
    pub fn sites(self) -> u32 {
        self.ramb36 + self.ramb18.div_ceil(2)
    }
}

impl std::ops::AddAssign for Brams {
    fn add_assign(&mut self, o: Brams) {
        self.ramb36 += o.ramb36;
        self.ramb18 += o.ramb18;
    }
}

/// One of the library's block modes: its address bits (counted at width 1), the widths its
/// ports take and how many read ports one block serves.
struct Mode {
    big: bool,
    cost: f64,
    abits: u32,
    widths: &'static [u32],
    read_ports: u32,
}

const DBITS: [u32; 7] = [1, 2, 4, 9, 18, 36, 72];

/// True dual port (two ports, each read or write) and simple dual port (one write, one read,
/// at the full width only), RAMB36 and RAMB18, in the library's order.
const MODES: [Mode; 4] = [
    Mode { big: false, cost: 129.0, abits: 14, widths: &[1, 2, 4, 9, 18], read_ports: 2 },
    Mode { big: true, cost: 257.0, abits: 15, widths: &[1, 2, 4, 9, 18, 36], read_ports: 2 },
    Mode { big: false, cost: 129.0, abits: 14, widths: &[36], read_ports: 1 },
    Mode { big: true, cost: 257.0, abits: 15, widths: &[72], read_ports: 1 },
];

/// The blocks of one memory of `depth` words (a power of two) × `width` bits with `reads` read
/// ports and a write port when `write`.
pub fn memory_blocks(depth: usize, width: u32, reads: u32, write: bool) -> Brams {
    let ports = reads + u32::from(write);
    let mut best: Option<(f64, Brams)> = None;
    for mode in &MODES {
        // A true dual-port block serves two ports, a simple dual-port one a write and a read.
        let copies = if mode.read_ports == 2 { ports.div_ceil(2) } else { reads.max(1) };
        for &w in mode.widths {
            let index = DBITS.iter().position(|&d| d == w).expect("a library width") as u32;
            let words = 1usize << (mode.abits - index);
            let regions = depth.div_ceil(words) as u64;
            let blocks = (regions * width as u64).div_ceil(w as u64) as u32 * copies;
            let mux = 0.5 * (regions - 1) as f64 * width as f64 * reads as f64;
            let cost = mode.cost * blocks as f64 + mux;
            if best.is_none_or(|(c, _)| cost < c) {
                let b =
                    if mode.big { Brams { ramb36: blocks, ramb18: 0 } } else { Brams { ramb36: 0, ramb18: blocks } };
                best = Some((cost, b));
            }
        }
    }
    best.expect("a mode").1
}

/// Read ports of memory `k` of `m`.
fn reads(m: &Module, k: usize) -> u32 {
    m.signals.iter().filter(|s| matches!(s.def, Def::RomRead { rom, .. } if rom == k)).count() as u32
}

/// Whether yosys puts memory `r` into block RAM (else LUTs, as the printers ask).
fn in_blocks(r: &Rom) -> bool {
    if r.write.is_some() { rom_depth(r.words.len()) > DISTRIBUTED_WORDS } else { r.words.len() >= BLOCK_WORDS }
}

/// The block RAMs of `m` with every instance below it (an instantiated module counts once per
/// instance).
pub fn brams(m: &Module) -> Brams {
    let mut out = Brams::default();
    for (k, r) in m.roms.iter().enumerate().filter(|(_, r)| in_blocks(r)) {
        out += memory_blocks(rom_depth(r.words.len()), r.width, reads(m, k), r.write.is_some());
    }
    for inst in &m.instances {
        out += brams(&inst.module);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What yosys 0.23 (`synth_xilinx -family xc5v`) made of the teapot core's memories, each
    /// synthesised alone: the leaf ROM 3 RAMB36, the two-port node ROM 17, the triangle ROM's
    /// three parts 28, 29 and 15 RAMB18, a stack 9 RAMB18.
    #[test]
    fn the_teapot_core_memories_take_what_yosys_maps() {
        let rb36 = |n| Brams { ramb36: n, ramb18: 0 };
        assert_eq!(memory_blocks(8192, 13, 1, false), rb36(3));
        assert_eq!(memory_blocks(8192, 73, 2, false), rb36(17));
        assert_eq!(memory_blocks(8192, 124, 1, false), rb36(28));
        assert_eq!(memory_blocks(8192, 128, 1, false), rb36(29));
        assert_eq!(memory_blocks(8192, 32, 1, false), Brams { ramb36: 0, ramb18: 15 });
        assert_eq!(memory_blocks(2048, 77, 1, true), Brams { ramb36: 0, ramb18: 9 });
        assert_eq!(Brams { ramb36: 77, ramb18: 33 }.sites(), 94);
    }
}
