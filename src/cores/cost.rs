//! Hardware cost without synthesis: latencies, ROM bits and a DSP48E count derived from the
//! netlist's multipliers, for sweeps that cannot afford yosys on every configuration.

use super::top::{CoreParams, core_module_with};
use crate::rtl::BinOp;
use crate::rtl::Module;
use crate::rtl::netlist::Def;
use crate::rtl::width::Ty;
use crate::scene::images::SceneRoms;
use serde::{Deserialize, Serialize};

/// Operand types of every multiplier in `m` and in every instance below it (an instantiated
/// module counts once per instance).
pub fn multipliers(m: &Module) -> Vec<(Ty, Ty)> {
    let mut out = Vec::new();
    for s in &m.signals {
        if let Def::Bin(BinOp::Mul, a, b) = s.def {
            out.push((m.signals[a.0 as usize].ty, m.signals[b.0 as usize].ty));
        }
    }
    for inst in &m.instances {
        out.extend(multipliers(&inst.module));
    }
    out
}

/// DSP48E slices yosys `synth_xilinx -family xc5v` uses for one multiplier. The DSP48E
/// multiplies 25 × 18 bits, both signed; a wider operand is cut into a signed top part of up
/// to 25 (18) bits and unsigned lower parts of 24 (17) bits, one slice per pair of parts.
/// yosys may put either operand on the 25-bit port, and picks the cheaper way. An unsigned
/// operand needs one more bit to be signed. Checked against yosys in `tests/hdl.rs`.
pub fn dsp48e_per_multiplier(a: Ty, b: Ty) -> u32 {
    let bits = |t: Ty| t.width + (!t.signed) as u32;
    let parts = |w: u32, port: u32| if w <= port { 1 } else { 1 + (w - port).div_ceil(port - 1) };
    let (a, b) = (bits(a), bits(b));
    (parts(a, 25) * parts(b, 18)).min(parts(b, 25) * parts(a, 18))
}

pub fn dsp48e_estimate(m: &Module) -> u32 {
    multipliers(m).into_iter().map(|(a, b)| dsp48e_per_multiplier(a, b)).sum()
}

/// What a configuration costs in hardware, as far as it is known without synthesis.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct CoreCost {
    /// Divider latency in cycles.
    pub div_latency: u32,
    /// Intersection pipeline latency in cycles.
    pub isect_latency: u32,
    /// Bits of the triangle, node and leaf ROMs (each rounded to a power-of-two depth).
    pub rom_bits: u64,
    /// DSP48E slices by `dsp48e_per_multiplier`.
    pub dsp48e_est: u32,
    /// Register bits of the netlist: flip-flops before synthesis moves delay lines into SRLs
    /// and DSP48E registers (it is where T shows: the divider's stages get narrower).
    pub register_bits: u64,
}

/// The cost of the whole core built for `roms` (ray id width 20, one quotient bit per stage).
pub fn core_cost(roms: &SceneRoms) -> crate::error::Result<CoreCost> {
    let p = CoreParams::new(roms, 20, 1, crate::cores::clock::DEFAULT_TARGET_MHZ);
    p.check()?;
    let core = core_module_with(&p, roms, false);
    let rom_bits = roms.rom_bits();
    Ok(CoreCost {
        div_latency: p.isect.div_latency(),
        isect_latency: p.isect.latency(),
        rom_bits,
        dsp48e_est: dsp48e_estimate(&core),
        register_bits: core.register_bits(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Counts yosys 0.x reported for single registered multipliers (signed unless noted).
    #[test]
    fn per_multiplier_counts_match_yosys_measurements() {
        let s = Ty::s;
        for (a, b, dsp) in [
            (25, 18, 1),
            (26, 18, 2),
            (30, 33, 4),
            (32, 32, 4),
            (49, 33, 4),
            (50, 18, 3),
            (18, 50, 3),
            (42, 17, 2),
            (18, 19, 1),
            (16, 16, 1),
        ] {
            assert_eq!(dsp48e_per_multiplier(s(a), s(b)), dsp, "{a}×{b}");
        }
        assert_eq!(dsp48e_per_multiplier(Ty::u(24), Ty::u(17)), 1);
    }
}
