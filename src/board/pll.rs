//! PLL settings for the board clocks: the oscillator to the board clock asked for, the
//! fastest clock not above it that the PLL makes. The ranges are the data sheets' (ECP5:
//! Lattice FPGA-DS-02012 table "sysCLOCK PLL Timing"; Virtex-5: DS202 "PLL Switching
//! Characteristics", speed grade -1).

/// EHXPLLL dividers (feedback from CLKOP): f_out = f_in · CLKFB_DIV / CLKI_DIV, the VCO at
/// f_out · CLKOP_DIV.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ecp5Pll {
    pub clki_div: u32,
    pub clkfb_div: u32,
    pub clkop_div: u32,
}

impl Ecp5Pll {
    /// Phase-detector input 3.125 MHz or more, VCO 400–800 MHz.
    pub const PFD_MIN: f64 = 3.125;
    pub const VCO: (f64, f64) = (400.0, 800.0);

    /// The settings whose output is the highest not above `target_mhz`, the VCO nearest its
    /// range's middle among equals (the search `ecppll` of Project Trellis makes, restricted to
    /// outputs not above the target: the board clock is a timing constraint).
    pub fn for_clock(in_mhz: f64, target_mhz: f64) -> Option<Ecp5Pll> {
        let mut best: Option<(f64, f64, Ecp5Pll)> = None;
        for clki_div in 1..=128u32 {
            let pfd = in_mhz / clki_div as f64;
            if pfd < Self::PFD_MIN {
                break;
            }
            for clkfb_div in 1..=80u32 {
                let out = pfd * clkfb_div as f64;
                if out > target_mhz + 1e-9 {
                    break;
                }
                for clkop_div in 1..=128u32 {
                    let vco = out * clkop_div as f64;
                    if vco < Self::VCO.0 || vco > Self::VCO.1 {
                        continue;
                    }
                    let key = (target_mhz - out, (vco - 600.0).abs());
                    if best.is_none_or(|b| key.0 < b.0 - 1e-9 || (key.0 < b.0 + 1e-9 && key.1 < b.1 - 1e-9)) {
                        best = Some((key.0, key.1, Ecp5Pll { clki_div, clkfb_div, clkop_div }));
                    }
                }
            }
        }
        best.map(|b| b.2)
    }

    pub fn out_mhz(&self, in_mhz: f64) -> f64 {
        in_mhz * self.clkfb_div as f64 / self.clki_div as f64
    }

    /// CLKOP's coarse phase for 0°: half the output divider, as `ecppll` sets it.
    pub fn cphase(&self) -> u32 {
        (self.clkop_div - 1) / 2
    }
}

/// Virtex-5 PLL_BASE: f_VCO = f_in · CLKFBOUT_MULT / DIVCLK_DIVIDE, f_out = f_VCO /
/// CLKOUT0_DIVIDE.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct V5Pll {
    pub divclk_divide: u32,
    pub clkfbout_mult: u32,
    pub clkout0_divide: u32,
}

impl V5Pll {
    /// Phase detector 19–400 MHz (DS202: F_INMIN … F_PFDMAX for -1), VCO 400–900 MHz.
    pub const PFD: (f64, f64) = (19.0, 400.0);
    pub const VCO: (f64, f64) = (400.0, 900.0);

    /// The settings whose output is the highest not above `target_mhz`; among equals the
    /// smallest input divider (the fastest phase detector), then the VCO nearest the middle of
    /// its range (away from both edges of DS202's range).
    pub fn for_clock(in_mhz: f64, target_mhz: f64) -> Option<V5Pll> {
        let mut best: Option<(f64, f64, V5Pll)> = None;
        for divclk_divide in 1..=52u32 {
            let pfd = in_mhz / divclk_divide as f64;
            if pfd < Self::PFD.0 {
                break;
            }
            if pfd > Self::PFD.1 {
                continue;
            }
            for clkfbout_mult in 1..=64u32 {
                let vco = pfd * clkfbout_mult as f64;
                if vco < Self::VCO.0 || vco > Self::VCO.1 {
                    continue;
                }
                for clkout0_divide in 1..=128u32 {
                    let out = vco / clkout0_divide as f64;
                    if out > target_mhz + 1e-9 {
                        continue;
                    }
                    // Input dividers come in rising order: a later one never wins a tie.
                    let key = (target_mhz - out, (vco - 0.5 * (Self::VCO.0 + Self::VCO.1)).abs());
                    let same_d = best.is_some_and(|b| b.2.divclk_divide == divclk_divide);
                    if best.is_none_or(|b| key.0 < b.0 - 1e-9 || (same_d && key.0 < b.0 + 1e-9 && key.1 < b.1 - 1e-9)) {
                        best = Some((key.0, key.1, V5Pll { divclk_divide, clkfbout_mult, clkout0_divide }));
                    }
                    break;
                }
            }
        }
        best.map(|b| b.2)
    }

    pub fn out_mhz(&self, in_mhz: f64) -> f64 {
        in_mhz * self.clkfbout_mult as f64 / self.divclk_divide as f64 / self.clkout0_divide as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ecp5_settings_stay_in_range_and_below_the_target() {
        for target in [25.0, 50.0, 66.0, 80.0, 90.0, 100.0, 133.0, 150.0, 200.0] {
            let p = Ecp5Pll::for_clock(25.0, target).unwrap();
            let out = p.out_mhz(25.0);
            assert!(out <= target + 1e-9 && out > target * 0.97, "{target}: {p:?} gives {out}");
            let vco = out * p.clkop_div as f64;
            assert!((400.0..=800.0).contains(&vco) && 25.0 / p.clki_div as f64 >= 3.125, "{p:?}");
        }
        // 25 MHz · 16 / 5 = 80 MHz, the VCO at 560 MHz (what `ecppll -i 25 -o 80` prints).
        assert_eq!(Ecp5Pll::for_clock(25.0, 80.0), Some(Ecp5Pll { clki_div: 5, clkfb_div: 16, clkop_div: 7 }));
        assert_eq!(Ecp5Pll { clki_div: 5, clkfb_div: 16, clkop_div: 7 }.cphase(), 3);
    }

    #[test]
    fn virtex5_settings_stay_in_range_and_below_the_target() {
        for target in [50.0, 80.0, 100.0, 125.0, 150.0, 233.0] {
            let p = V5Pll::for_clock(100.0, target).unwrap();
            let out = p.out_mhz(100.0);
            assert!(out <= target + 1e-9 && out > target * 0.97, "{target}: {p:?} gives {out}");
            let vco = 100.0 * p.clkfbout_mult as f64 / p.divclk_divide as f64;
            assert!((400.0..=900.0).contains(&vco), "{p:?}");
        }
        // 80 MHz: 100 · 8 / 1 / 10, the VCO at 800 MHz (400 · 2 / 1 / 5 would sit on the edge).
        assert_eq!(
            V5Pll::for_clock(100.0, 80.0),
            Some(V5Pll { divclk_divide: 1, clkfbout_mult: 8, clkout0_divide: 10 })
        );
    }
}
