//! The LUTs `fxrt synth --family ecp5` gives a module, estimated from the netlist alone (no
//! yosys): what issue 30's `--device` counts beside the multipliers, block RAM and flip-flops.
//!
//! Three parts, each from the operators' widths as yosys `synth_ecp5` maps them:
//! - `ccu2c`: carry chains, two bits a cell, of every adder, subtractor, negation and ordered
//!   compare;
//! - `dpr16x4`: LUT RAM, a 16-word × 4-bit cell per 16 words, 4 bits and read port of every
//!   memory kept in LUTs (`blocks::Blocks::lut_ram_bits`'s memories and the delay-line rings);
//! - `lut4`: the rest of the logic — a LUT per bit of a two-way select, a LUT per two bits of
//!   a compare for equality (four against a constant), a LUT per three bits of AND and OR
//!   (they merge into their neighbours), one per bit of XOR, half a LUT per bit and arm of a
//!   case select, the selects after LUT RAM deeper than 16 words, and ROMs kept in LUTs.
//!
//! nextpnr counts what it places as `TRELLIS_COMB` (`lut4` in the reports): a LUT4 each, two
//! per CCU2C, and `COMB_PER_DPR` per DPR16X4 (its two RAM slices' four LUTs, the write slice
//! and the through-LUTs packing adds): `Luts::comb`. docs/HDL.md compares it with placed
//! and synthesised cores.

use crate::rtl::netlist::{Def, Module, Rom};
use crate::rtl::width::{BinOp, UnOp};
use crate::scene::rom::rom_depth;

/// `TRELLIS_COMB` cells nextpnr places per DPR16X4 yosys maps: 6.39–6.45 on three placed cores
/// (the default core, the four-unit two-pipeline core and a core of 4 × 32 slots), as
/// `(COMB − LUT4 − 2 CCU2C) / DPR16X4` of their yosys statistics and nextpnr reports.
pub const COMB_PER_DPR: f64 = 6.4;

/// Xilinx LUT6 (with those used as shift registers and LUT RAM) per LUT4 `Luts::comb` counts
/// for the same core: yosys 0.23 `synth_xilinx -family xc5v` mapped the XC5VLX110T's fit to
/// 12,150 (docs/HDL.md).
pub const LUT6_PER_LUT4: f64 = 0.39;

/// What yosys maps beyond the logic rules count: their LUT4 are 89–92 % of yosys's for the
/// default core's traversal unit, closest-hit unit and intersection pipeline synthesised alone
/// (reset and enable logic folded into LUTs, the read-first bypasses of LUT RAM, the ORs of
/// wide selects the rules take as free), so the logic count is scaled up by this.
pub const LOGIC_SCALE: f64 = 1.1;

/// Estimated cells of a module and everything it instantiates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Luts {
    /// LUT4s of the logic (not carry chains, not LUT RAM).
    pub lut4: f64,
    /// Carry cells, two bits each.
    pub ccu2c: f64,
    /// LUT RAM cells, 16 words × 4 bits, one write and one read port each.
    pub dpr16x4: f64,
}

impl std::ops::AddAssign for Luts {
    fn add_assign(&mut self, o: Luts) {
        self.lut4 += o.lut4;
        self.ccu2c += o.ccu2c;
        self.dpr16x4 += o.dpr16x4;
    }
}

impl Luts {
    /// The `TRELLIS_COMB` cells nextpnr would place (its reports' LUT4 count).
    pub fn comb(&self) -> u64 {
        (LOGIC_SCALE * self.lut4 + 2.0 * self.ccu2c + COMB_PER_DPR * self.dpr16x4).round() as u64
    }

    /// The LUT6 yosys would map on a Virtex-5 or 7-series part (`LUT6_PER_LUT4`).
    pub fn lut6(&self) -> u64 {
        (self.comb() as f64 * LUT6_PER_LUT4).round() as u64
    }
}

fn half_up(w: u32) -> f64 {
    w.div_ceil(2) as f64
}

/// A memory's cells when it is kept in LUTs: LUT RAM (with its read ports) for a RAM, logic for
/// a ROM; nothing for a block memory.
fn memory(r: &Rom, reads: usize, block_module: bool) -> Luts {
    if block_module || super::blocks::inferred_dp16kd(r).is_some() {
        return Luts::default();
    }
    let depth = rom_depth(r.words.len()) as f64;
    let sixteens = (depth / 16.0).ceil();
    let width = r.width as f64;
    if r.write.is_some() {
        let reads = reads.max(1) as f64;
        // The select after the cells: a LUT per bit and two cells more, per read port.
        let select = (sixteens - 1.0) * width / 2.0 * reads;
        Luts { dpr16x4: sixteens * (width / 4.0).ceil() * reads, lut4: select + sixteens, ..Luts::default() }
    } else {
        Luts { lut4: sixteens * width * reads.max(1) as f64, ..Luts::default() }
    }
}

/// Cells of one signal's operator (`w` its width).
fn operator(m: &Module, def: &Def, w: u32) -> Luts {
    let width = |id: &crate::rtl::netlist::SigId| m.signals[id.0 as usize].ty.width;
    let const_value = |id: &crate::rtl::netlist::SigId| match m.signals[id.0 as usize].def {
        Def::Const(c) => Some(c),
        _ => None,
    };
    let is_const = |id: &crate::rtl::netlist::SigId| const_value(id).is_some();
    let is_sum =
        |id: &crate::rtl::netlist::SigId| matches!(m.signals[id.0 as usize].def, Def::Bin(BinOp::Add | BinOp::Sub, ..));
    // One bit, or one bit extended.
    let one_bit = |id: &crate::rtl::netlist::SigId| match m.signals[id.0 as usize].def {
        Def::Un(UnOp::Resize(_), x) => width(&x) == 1,
        _ => width(id) == 1,
    };
    let lut4 = |x: f64| Luts { lut4: x, ..Luts::default() };
    match def {
        // A bit added to a sum is the sum's carry in (`x + y + c` is one chain).
        Def::Bin(BinOp::Add | BinOp::Sub, a, b)
            if [a, b].iter().any(|&id| is_sum(id)) && [a, b].iter().any(|&id| one_bit(id)) =>
        {
            Luts::default()
        }
        // Below a constant operand's lowest one bit the sum is the other operand's bits.
        Def::Bin(BinOp::Add | BinOp::Sub, a, b) => {
            let low = [a, b].iter().filter_map(|&id| const_value(id)).map(|c| c.trailing_zeros().min(w)).max();
            Luts { ccu2c: half_up(w - low.unwrap_or(0)), ..Luts::default() }
        }
        Def::Un(UnOp::Neg, _) => Luts { ccu2c: half_up(w), ..Luts::default() },
        // Against zero a compare is the sign bit.
        Def::Bin(BinOp::Lt | BinOp::Le, _, b) if const_value(b) == Some(0) => Luts::default(),
        Def::Bin(BinOp::Lt | BinOp::Le, a, b) => Luts { ccu2c: half_up(width(a).max(width(b))), ..Luts::default() },
        Def::Bin(BinOp::Eq | BinOp::Ne, a, b) => {
            let bits = width(a).max(width(b)) as f64;
            let per = if is_const(a) || is_const(b) { 4.0 } else { 2.0 };
            let first = (bits / per).ceil();
            lut4(first + ((first - 1.0) / 3.0).ceil())
        }
        Def::Bin(BinOp::And | BinOp::Or, ..) => lut4(w as f64 / 3.0),
        Def::Bin(BinOp::Xor, ..) => lut4(w as f64),
        Def::Mux { t, f, .. } => lut4(if is_const(t) || is_const(f) { w as f64 / 2.0 } else { w as f64 }),
        Def::Case { arms, .. } => lut4(w as f64 * arms.len() as f64 / 2.0),
        _ => Luts::default(),
    }
}

/// The module's own cells, without its instances.
fn own(m: &Module) -> Luts {
    if m.name.starts_with(super::dsp::DSP_MODULE_PREFIX) || m.name.starts_with(crate::cores::mul::DSP48_MODULE_PREFIX) {
        return Luts::default();
    }
    let block_module = super::blocks::is_block_module(m);
    let mut out = Luts::default();
    for s in &m.signals {
        out += operator(m, &s.def, s.ty.width);
    }
    for (k, r) in m.roms.iter().enumerate() {
        let reads = m.signals.iter().filter(|s| matches!(s.def, Def::RomRead { rom, .. } if rom == k)).count();
        out += memory(r, reads, block_module);
    }
    out
}

/// The estimated cells of `m` with every instance below it.
pub fn luts(m: &Module) -> Luts {
    let mut out = own(m);
    for inst in &m.instances {
        out += luts(&inst.module);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cores::core_params::{CoreParams, CoreSpec};
    use crate::cores::top::core_module_with;
    use crate::params::Params;
    use crate::rtl::Ty;
    use crate::rtl::build::Builder;
    use crate::scene::images::SceneRoms;
    use crate::scene::{Scene, SceneSource};

    /// The rules on small cases: a 32-bit sum is 16 carry cells and a bit added to it rides in
    /// its carry; a compare against zero is the sign bit; a sum with 8 is carried from bit 3;
    /// a 64 × 8 RAM read at two ports is 4 × 2 cells a port.
    #[test]
    fn carry_chains_and_lut_ram_are_counted_as_yosys_maps_them() {
        let b = Builder::new("t");
        let (x, y, c) = (b.input("x", Ty::u(32)), b.input("y", Ty::u(32)), b.input("c", Ty::BIT));
        let sum = (x + y).resize(32);
        b.output("s", (sum + c.resize(32)).resize(32));
        b.output("neg", b.input("z", Ty::s(32)).lt(0));
        b.output("plus8", (y + 8).resize(32));
        let mem = b.ram("m", 8, vec![0; 64]);
        let (a0, a1) = (b.input("a0", Ty::u(6)), b.input("a1", Ty::u(6)));
        b.ram_write(mem, c, a0, x.slice(0, 8));
        b.output("r0", b.read("r0", mem, a0));
        b.output("r1", b.read("r1", mem, a1));
        let l = luts(&b.finish());
        assert_eq!(l.ccu2c, 16.0 + 15.0, "{l:?}");
        assert_eq!(l.dpr16x4, 16.0, "{l:?}");
    }

    /// Against what nextpnr placed (`TRELLIS_COMB`, docs/TIMING.md) and, for a core not placed,
    /// yosys's cells counted the same way (LUT4 + 2 CCU2C + `COMB_PER_DPR` DPR16X4): within 3 %.
    #[test]
    fn core_estimates_are_within_three_percent_of_the_placed_and_synthesised_counts() {
        let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
        let roms = SceneRoms::of(&scene);
        for ([slots, units], measured) in [
            // The default core, placed (generated/measured, sha256 437541c1…).
            ([64, 2], 32_925.0),
            // One unit of 16 slots, yosys 0.70 synth_ecp5: 5,937 LUT4, 2,284 CCU2C, 670 DPR16X4.
            ([16, 1], 5_937.0 + 2.0 * 2_284.0 + COMB_PER_DPR * 670.0),
        ] {
            let p = CoreParams::shaped(&roms, &CoreSpec { slots, units, ..CoreSpec::default() });
            let got = luts(&core_module_with(&p, &roms, false)).comb() as f64;
            assert!((got / measured - 1.0).abs() < 0.03, "{units} × {slots}: {got} against {measured}");
        }
    }
}
