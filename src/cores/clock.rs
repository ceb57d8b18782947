//! Pipelining for a clock target: one number (`--target-mhz`) decides where the cores put
//! registers. The cores are described with their finest stages; a lower target merges stages
//! (`Policy::merge`) and builds products with fewer registers (`MulStyle`), so only the
//! latencies move and every result stays bit-identical.
//!
//! The thresholds are estimates from measured ECP5 figures (LFE5U-85F, speed 6, nextpnr;
//! `../shared/docs/ANCHORS.md` and docs/TIMING.md): a product made in one clock reaches about
//! 84 MHz; 18×18 pieces with registers around them about 138 MHz, with the DSP block's
//! pipeline register about 216 MHz; one 32–64-bit carry chain between registers runs at
//! 150–200 MHz, two in series at about half that. docs/TIMING.md has what each target
//! actually reaches.

use super::mul::{MulStyle, Piece};

/// The default clock target, MHz (chosen by measurement: docs/TIMING.md).
pub const DEFAULT_TARGET_MHZ: u32 = 150;

/// From this target a value that crosses the die between two placed groups (a plane distance
/// from the DSP column to the traversal's compares, a leaf from the node ROM's word to the
/// leaf queue, a product to its subtractor) gets a register at each end: the route alone took
/// 3.2–3.4 ns of a 6.67 ns clock in the placed default core (DECISIONS 126).
pub const LANDING_FROM_MHZ: u32 = 141;

/// More traversal units than this spread a core over the die (four fill three quarters of the
/// LFE5U-85F's LUTs): from the landing target on, such a core lands its plane products in
/// fabric registers, takes a ray done through a second register before the closest-hit units,
/// and copies the has-best bit per result field. In the four-unit core each of these paths was
/// among the slowest at a placement seed (DECISIONS 133); the two-unit default met 150 MHz
/// without them, and its netlist (and measured clock) stays as it is.
pub const SPREAD_FROM_UNITS: u32 = 3;

/// Whether a core of `units` traversal units at `target` gets the spread core's registers
/// (`SPREAD_FROM_UNITS`).
pub fn spread(units: u32, target: ClockTarget) -> bool {
    units >= SPREAD_FROM_UNITS && target.splits(LANDING_FROM_MHZ)
}

/// Targets the cores are pipelined for, MHz: below the lowest the description is the
/// thesis-like one with one-clock products; above the highest nothing more is split.
pub const TARGET_RANGE: (u32, u32) = (50, 400);

/// A clock target in MHz.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClockTarget(pub u32);

impl Default for ClockTarget {
    fn default() -> Self {
        ClockTarget(DEFAULT_TARGET_MHZ)
    }
}

impl ClockTarget {
    pub fn mhz(self) -> u32 {
        self.0
    }

    /// Checks the range, naming the parameter.
    pub fn check(self) -> crate::error::Result<()> {
        let (lo, hi) = TARGET_RANGE;
        if !(lo..=hi).contains(&self.0) {
            return Err(crate::error::Error::param(
                "target-mhz",
                format!("{} is out of range: must be {lo}..={hi}", self.0),
            ));
        }
        Ok(())
    }

    /// How products are built.
    pub fn mul_style(self) -> MulStyle {
        match self.0 {
            0..=75 => MulStyle::COMBINATIONAL,
            76..=125 => MulStyle { dsp_regs: 2, levels_per_stage: 2, piece: Piece::Mult18 },
            // Measured at 150 MHz with two tree levels per stage: 108.7 MHz, the path a DSP
            // output through two adders (docs/TIMING.md).
            126..=175 => MulStyle { dsp_regs: 3, levels_per_stage: 1, piece: Piece::Mult18 },
            // At 200 MHz the DSP column's output routed to the first tree adder (2.8 ns) held
            // the intersection pipeline at 190.6 MHz: a fabric register lands it first.
            _ => MulStyle { dsp_regs: 4, levels_per_stage: 1, piece: Piece::Mult18 },
        }
    }

    /// Whether a stage that only splits a chain of logic (a mux before a multiplier, two
    /// adders in series) gets its registers at this target: `from` is the lowest target
    /// that needs it.
    pub fn splits(self, from: u32) -> bool {
        self.0 >= from
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn higher_targets_never_have_fewer_registers() {
        let mut last = (0, 0);
        for mhz in TARGET_RANGE.0..=TARGET_RANGE.1 {
            let s = ClockTarget(mhz).mul_style();
            let regs = (s.dsp_regs, if s.levels_per_stage == 0 { 0 } else { 4 - s.levels_per_stage });
            assert!(regs >= last, "{mhz} MHz: {regs:?} after {last:?}");
            last = regs;
        }
        assert!(ClockTarget(49).check().is_err() && ClockTarget(401).check().is_err());
        assert!(ClockTarget(DEFAULT_TARGET_MHZ).check().is_ok());
    }
}
