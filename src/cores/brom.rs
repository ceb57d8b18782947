//! Block ROMs read over two or three clocks: `data` is the word at `addr` `cycles` clocks
//! after `addr` (a synchronous read, then one or two more registers with no logic between).
//!
//! Every ROM of the scene (node, leaf, the triangle words) is one of these modules. The pair of
//! registers is what a block RAM with its output register does, and a block RAM without it is
//! too slow for the clock: nextpnr gives an ECP5 DP16KD 5.6 ns from clock to data without
//! its output register (`REGMODE = NOREG`), so even a ROM word going straight into a fabric
//! register missed 150 MHz once routed (the teapot's traversal unit, 91.8 MHz). Yosys never
//! infers `REGMODE = OUTREG` (yosys issue 5814: the output register is only available by
//! instantiating the primitive), so `fxrt synth --family ecp5` replaces the body of each
//! module named `fxrt_brom_…` by DP16KD primitives with their output register
//! (`fpga::ecp5::bram`), the way it places the multiplier pieces in MULT18X18Ds. The generated
//! HDL stays portable, and every simulator runs it as written here.
//!
//! A third clock is a fabric register after the block's output register: a design of many
//! blocks spreads them over the die, and the route from a block to the logic it feeds was
//! measured at up to 5.7 ns (the teapot's node ROM, 37 blocks, 134.9 MHz with two clocks), so
//! the block's word first goes into a flip-flop the placer can put between the two.

use crate::rtl::build::{Builder, S};
use crate::rtl::{Module, Ty};
use crate::scene::rom::rom_addr_bits;
use std::rc::Rc;

/// The name prefix of block ROM modules (the ECP5 flow recognises them by it).
pub const BROM_PREFIX: &str = "fxrt_brom_";

/// ROMs of at least this many words are block RAM; smaller ones are LUTs (yosys 0.70 makes a
/// 73-bit ROM of 64 words of LUTs and one of 128 words of DP16KDs).
pub const BLOCK_WORDS: usize = 128;

/// The clocks a ROM of `words` words is read in: 3 for block RAM (the fabric register after the
/// block), 2 for a LUT ROM (its read register and one more, as close as any logic).
pub fn read_cycles(words: usize) -> u32 {
    if words >= BLOCK_WORDS { 3 } else { 2 }
}

/// The clocks a triangle ROM of `words` words is read in: one more than `read_cycles` for block
/// RAM. The triangle ROMs are the widest (the teapot's 121 blocks across the die), and split by
/// depth into banks their words meet in a multiplexer: a block's word through it into the
/// fabric register was the default core's slowest path at seed 2 (7.66 ns). The fourth clock
/// is a fabric register per bank before the multiplexer (`fpga::ecp5::bram`).
pub fn tri_read_cycles(words: usize) -> u32 {
    read_cycles(words) + u32::from(words >= BLOCK_WORDS)
}

/// The ROM `fxrt_brom_{name}` of `width`-bit words: ports `addr` (the ROM's address bits) →
/// `data`, `cycles` (2 to 4) clocks later.
pub fn brom_module(name: &str, width: u32, words: Vec<u128>, cycles: u32) -> Module {
    brom_module_ports(name, width, words, cycles, 1)
}

/// The same with `ports` (1 or 2) read ports: `addr`, `data` and, for two, `addr_b`, `data_b`
/// (a block RAM's second port: two traversal units share one node ROM), named
/// `fxrt_brom_{name}_2p`.
pub fn brom_module_ports(name: &str, width: u32, words: Vec<u128>, cycles: u32, ports: u32) -> Module {
    assert!((2..=4).contains(&cycles), "a block ROM reads in 2 to 4 clocks");
    assert!((1..=2).contains(&ports), "a block ROM has one or two read ports");
    let suffix = if ports == 2 { "_2p" } else { "" };
    let b = Builder::new(&format!("{BROM_PREFIX}{name}{suffix}"));
    let bits = rom_addr_bits(words.len());
    let addrs: Vec<S> = ["addr", "addr_b"][..ports as usize].iter().map(|n| b.input(n, Ty::u(bits))).collect();
    let mem = b.rom("mem", width, words);
    for (k, addr) in addrs.into_iter().enumerate() {
        let x = ["", "_b"][k];
        let word = b.read(&format!("word{x}"), mem, addr);
        // Plain registers, not a delay line (which a synthesis tool may map to shift-register
        // LUTs): the first is the block's output register, the second a fabric flip-flop.
        let mut data = b.delay(&format!("data{x}_r"), word);
        for more in 3..=cycles {
            data = b.delay(&format!("data{x}_r{}", "r".repeat(more as usize - 2)), data);
        }
        b.output(&format!("data{x}"), data);
    }
    b.finish()
}

/// The clocks of a block ROM module's read: the synchronous read and its registers.
pub fn brom_cycles(m: &Module) -> u32 {
    let regs = m.signals.iter().filter(|s| matches!(s.def, crate::rtl::netlist::Def::Reg { .. })).count() as u32;
    1 + regs / m.outputs.len() as u32
}

/// In `b`: the block ROM `name` read at `addr` (instance `label`); its word `cycles` clocks
/// later.
pub fn brom<'b>(
    b: &'b Builder,
    label: &str,
    name: &str,
    width: u32,
    words: Vec<u128>,
    addr: S<'b>,
    cycles: u32,
) -> S<'b> {
    let m = Rc::new(brom_module(name, width, words, cycles));
    b.instance(label, &m, &[addr]).get("data")
}

/// The name prefix of block RAM modules (`bram_module`; the ECP5 flow recognises them by it).
pub const BRAM_PREFIX: &str = "fxrt_bram_";

/// The RAM `fxrt_bram_{name}` of `words` × `width` bits, zeros at power-up: a write port (`we`,
/// `waddr`, `wdata`) and a read port (`raddr` → `data`, two clocks later: the block's read and
/// its output register, read-first). A traversal unit's stack: a block RAM whose word went
/// straight from the block into logic (no output register: 5.6 ns on the ECP5) would not make
/// the clock; `fxrt synth --family ecp5` builds it of DP16KDs with their output register.
pub fn bram_module(name: &str, width: u32, words: usize) -> Module {
    let b = Builder::new(&format!("{BRAM_PREFIX}{name}"));
    let bits = rom_addr_bits(words);
    let we = b.input("we", Ty::BIT);
    let waddr = b.input("waddr", Ty::u(bits));
    let wdata = b.input("wdata", Ty::u(width));
    let raddr = b.input("raddr", Ty::u(bits));
    let mem = b.ram("mem", width, vec![0; words]);
    b.ram_write(mem, we, waddr, wdata);
    let word = b.read("word", mem, raddr);
    b.output("data", b.delay("data_r", word));
    b.finish()
}

/// In `b`: the RAM `name` (instance `label`); the word at `raddr` two clocks later.
#[allow(clippy::too_many_arguments)]
pub fn bram<'b>(
    b: &'b Builder,
    label: &str,
    name: &str,
    width: u32,
    words: usize,
    we: S<'b>,
    waddr: S<'b>,
    wdata: S<'b>,
    raddr: S<'b>,
) -> S<'b> {
    let m = Rc::new(bram_module(name, width, words));
    b.instance(label, &m, &[we, waddr, wdata, raddr]).get("data")
}

/// The two-port form: the words at `addr` and `addr_b`, `cycles` clocks later.
#[allow(clippy::too_many_arguments)]
pub fn brom2<'b>(
    b: &'b Builder,
    label: &str,
    name: &str,
    width: u32,
    words: Vec<u128>,
    addr: S<'b>,
    addr_b: S<'b>,
    cycles: u32,
) -> (S<'b>, S<'b>) {
    let m = Rc::new(brom_module_ports(name, width, words, cycles, 2));
    let p = b.instance(label, &m, &[addr, addr_b]);
    (p.get("data"), p.get("data_b"))
}

/// A ROM read at each of `addrs` (`cycles` clocks later): one block ROM's two ports per two
/// addresses, a block ROM of one port for an odd one left; `label(k)` names the k-th ROM.
pub fn rom_reads<'b>(
    b: &'b Builder,
    label: &dyn Fn(usize) -> String,
    name: &str,
    width: u32,
    image: &[u128],
    addrs: &[S<'b>],
    cycles: u32,
) -> Vec<S<'b>> {
    let mut words = Vec::new();
    for (k, two) in addrs.chunks(2).enumerate() {
        match *two {
            [a, c] => {
                let (wa, wc) = brom2(b, &label(k), name, width, image.to_vec(), a, c, cycles);
                words.extend([wa, wc]);
            }
            _ => words.push(brom(b, &label(k), name, width, image.to_vec(), two[0], cycles)),
        }
    }
    words
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::sim::Sim;

    /// The word at an address is on `data` `cycles` clocks after the address.
    #[test]
    fn reads_over_two_or_three_clocks() {
        for cycles in [2, 3, 4] {
            let words: Vec<u128> = (0..5).map(|k| 100 + k).collect();
            let m = brom_module("t", 8, words, cycles);
            assert_eq!((m.name.as_str(), brom_cycles(&m)), ("fxrt_brom_t", cycles));
            let mut sim = Sim::new(&m);
            let (addr, data) = (m.handle(m.inputs[0]), m.handle(m.outputs[0].1));
            let seq = [3, 1, 4, 0, 2, 2, 1];
            let mut got = Vec::new();
            for &a in &seq {
                sim.set(addr, a);
                sim.tick();
                got.push(sim.get(data));
            }
            // After edge k + 1, data is the word at the address of edge k + 2 − cycles.
            let c = cycles as usize;
            for k in c - 1..seq.len() {
                assert_eq!(got[k], 100 + seq[k + 1 - c], "{cycles} clocks, edge {}", k + 1);
            }
        }
    }

    /// The two-port form: each port reads its own address, `cycles` clocks later.
    #[test]
    fn two_ports_read_independently() {
        for cycles in [2, 3, 4] {
            let m = brom_module_ports("t", 8, (0..6).map(|k| 50 + k).collect(), cycles, 2);
            assert_eq!((m.name.as_str(), brom_cycles(&m)), ("fxrt_brom_t_2p", cycles));
            let mut sim = Sim::new(&m);
            let (a, b) = (m.handle(m.inputs[0]), m.handle(m.inputs[1]));
            let (da, db) = (m.handle(m.outputs[0].1), m.handle(m.outputs[1].1));
            let seq = [(3, 5), (1, 0), (4, 4), (0, 2), (2, 1), (5, 3)];
            let mut got = Vec::new();
            for &(x, y) in &seq {
                sim.set(a, x);
                sim.set(b, y);
                sim.tick();
                got.push((sim.get(da), sim.get(db)));
            }
            let c = cycles as usize;
            for k in c - 1..seq.len() {
                let (x, y) = seq[k + 1 - c];
                assert_eq!(got[k], (50 + x, 50 + y), "{cycles} clocks, edge {}", k + 1);
            }
        }
    }
}
