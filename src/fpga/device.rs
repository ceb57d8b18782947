//! The devices fxrt fits cores to (`--device`, issue 30): what each holds of logic, flip-flops,
//! multipliers and block RAM. Figures from the vendors' data sheets — Lattice FPGA-DS-02012
//! (ECP5 family: LFE5U-85F), Xilinx DS100 (Virtex-5 family overview: XC5VLX110T) and DS180
//! (7 series overview: XC7A100T) — and for the LFE5U-85F also nextpnr-ecp5's utilisation
//! report (83,640 TRELLIS_COMB and TRELLIS_FF, 156 MULT18X18D, 208 DP16KD).

use serde::{Deserialize, Serialize};

/// The devices `--device` names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Device {
    /// Lattice ECP5 LFE5U-85F (the ULX3S board's part; placed and routed here with nextpnr).
    #[value(name = "lfe5u-85f")]
    Lfe5u85f,
    /// Xilinx Virtex-5 XC5VLX110T (the thesis's part, the ML509 board's).
    #[value(name = "xc5vlx110t")]
    Xc5vlx110t,
    /// Xilinx Artix-7 XC7A100T.
    #[value(name = "xc7a100t")]
    Xc7a100t,
}

/// What a device holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Capacity {
    /// Look-up tables: LUT4 on the ECP5, LUT6 on Virtex-5 and 7 series.
    pub luts: u32,
    pub lut_inputs: u32,
    pub ffs: u32,
    /// Hard multipliers: MULT18X18D (ECP5), DSP48E (Virtex-5), DSP48E1 (7 series). Each
    /// multiplies 18 × 18 signed bits or more (the DSP48s 25 × 18).
    pub multipliers: u32,
    /// Block RAMs: DP16KD (18 Kb) on the ECP5, RAMB36 (36 Kb) on the Xilinx parts.
    pub block_rams: u32,
    pub block_ram_kbits: u32,
}

impl Device {
    pub const ALL: [Device; 3] = [Device::Lfe5u85f, Device::Xc5vlx110t, Device::Xc7a100t];

    pub const fn name(self) -> &'static str {
        match self {
            Device::Lfe5u85f => "LFE5U-85F",
            Device::Xc5vlx110t => "XC5VLX110T",
            Device::Xc7a100t => "XC7A100T",
        }
    }

    pub const fn capacity(self) -> Capacity {
        match self {
            Device::Lfe5u85f => Capacity {
                luts: 83_640,
                lut_inputs: 4,
                ffs: 83_640,
                multipliers: 156,
                block_rams: 208,
                block_ram_kbits: 18,
            },
            Device::Xc5vlx110t => Capacity {
                luts: 69_120,
                lut_inputs: 6,
                ffs: 69_120,
                multipliers: 64,
                block_rams: 148,
                block_ram_kbits: 36,
            },
            Device::Xc7a100t => Capacity {
                luts: 63_400,
                lut_inputs: 6,
                ffs: 126_800,
                multipliers: 240,
                block_rams: 135,
                block_ram_kbits: 36,
            },
        }
    }

    /// The hard multiplier a core built for the device cuts its products for.
    pub const fn piece(self) -> crate::cores::mul::Piece {
        match self {
            Device::Lfe5u85f => crate::cores::mul::Piece::Mult18,
            Device::Xc5vlx110t | Device::Xc7a100t => crate::cores::mul::Piece::Dsp48,
        }
    }

    /// The `synth --family` that maps cores for the device.
    pub const fn family(self) -> &'static str {
        match self {
            Device::Lfe5u85f => "ecp5",
            Device::Xc5vlx110t => "xc5v",
            Device::Xc7a100t => "xc7",
        }
    }

    /// Block RAM in kilobits (the `--bram-kbits` budget a device gives).
    pub const fn bram_kbits(self) -> u64 {
        let c = self.capacity();
        c.block_rams as u64 * c.block_ram_kbits as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The data sheets' block RAM totals: 3,744 Kb (LFE5U-85F), 5,328 Kb (XC5VLX110T),
    /// 4,860 Kb (XC7A100T).
    #[test]
    fn block_ram_totals_are_the_data_sheets() {
        let kbits: Vec<u64> = Device::ALL.iter().map(|d| d.bram_kbits()).collect();
        assert_eq!(kbits, [3_744, 5_328, 4_860]);
    }
}
