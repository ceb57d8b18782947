//! The block ROMs (`cores::brom`, modules `fxrt_brom_…`) as ECP5 DP16KD primitives with their
//! output register, for place and route only.
//!
//! Yosys maps a ROM to DP16KD with `REGMODE = NOREG` and never absorbs a second register into
//! the block's output register (yosys issue 5814: only by instantiating the primitive), and
//! nextpnr times a DP16KD without it at 5.6 ns from clock to data: a ROM word going straight
//! into a register missed 150 MHz (the teapot's traversal, 91.8 MHz). So `fxrt synth --family
//! ecp5` replaces the body of each block ROM module by DP16KDs in `REGMODE_A = "OUTREG"` —
//! the module's read register and output register are the block's own — the way
//! `ecp5_dsp` puts multiplier pieces in MULT18X18Ds. The ports and the cycle behaviour are the
//! generated module's, which every simulator checks.
//!
//! A ROM whose depth fills its configuration is a row of blocks side by side at the widest
//! data width that covers the depth (1K×18, 2K×9, 4K×4, 8K×2, 16K×1), with no multiplexer
//! after them. A ROM that a power of two overshoots is split by depth into banks (`banks`):
//! the teapot's 6,320 triangles of 284 bits take 121 blocks as 4K×4 + 2K×9 + 1K×18 where
//! 8K×2 took 142, its 4,450 nodes 24 where they took 37 (issue 12: the blocks saved hold the
//! second node ROM of four traversal units). The banks' words meet in a one-hot multiplexer
//! between the blocks' output registers and the fabric register. ROMs of fewer than
//! `MIN_WORDS` words are left as yosys infers them (LUTs).
//!
//! The initial contents follow yosys's own DP16KD mapping (`share/lattice/brams_map_16kd.v`
//! with `memory_libmap`): the block is 1,024 rows of 18 bits, INITVAL_00 … INITVAL_3F hold 16
//! rows each in 20-bit slots; a 9- or 18-bit word sits in consecutive row bits, a 1-, 2- or
//! 4-bit word in the 16 data bits of a row (bits 0–7 and 9–16, not the ninth bits). The port's
//! address is on ADA13 down to ADA(log2(16K / depth)). A test checks that these INITVALs and
//! connections are what yosys itself infers for the same ROM at each width.

use crate::rtl::netlist::Module;
use std::fmt::Write;

/// Block ROMs of fewer words stay as yosys infers them: LUTs.
pub const MIN_WORDS: usize = crate::cores::brom::BLOCK_WORDS;

/// (data width, depth) of the DP16KD configurations, widest first.
pub const CONFIGS: [(u32, usize); 5] = [(18, 1024), (9, 2048), (4, 4096), (2, 8192), (1, 16384)];

/// The widest configuration holding `depth` words, if any.
pub fn config(depth: usize) -> Option<(u32, usize)> {
    CONFIGS.iter().copied().find(|&(_, d)| d >= depth)
}

/// The 64 INITVAL parameters (320 bits each, as hex) of the block holding bits [lsb, lsb + w)
/// of each word, in data width `w`.
pub fn initvals(words: &[u128], lsb: u32, w: u32) -> Vec<String> {
    let mut bits = vec![false; 64 * 320];
    for (a, &word) in words.iter().enumerate() {
        for b in 0..w {
            if lsb + b >= 128 || (word >> (lsb + b)) & 1 == 0 {
                continue;
            }
            let k = a * w as usize + b as usize;
            let (row, col) = if w >= 9 { (k / 18, k % 18) } else { (k / 16, k % 16 + usize::from(k % 16 >= 8)) };
            bits[(row / 16) * 320 + (row % 16) * 20 + col] = true;
        }
    }
    bits.chunks(320)
        .map(|c| {
            (0..80)
                .rev()
                .map(|d| {
                    let nibble = (0..4).fold(0u32, |acc, i| acc | (u32::from(c[d * 4 + i]) << i));
                    char::from_digit(nibble, 16).expect("a nibble")
                })
                .collect()
        })
        .collect()
}

/// Words of a ROM's last bank small enough to be LUTs rather than a block.
pub const LUT_TAIL: usize = 128;

/// One bank of a block ROM split by depth: its words [base, base + 2^abits), in DP16KDs of data
/// width `w` side by side, or in LUTs when `w == 0` (a short tail).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bank {
    pub base: usize,
    pub abits: u32,
    pub w: u32,
}

impl Bank {
    pub fn blocks(&self, width: u32) -> usize {
        if self.w == 0 { 0 } else { width.div_ceil(self.w) as usize }
    }
}

/// How a ROM of `words` words of `width` bits is laid out in DP16KDs: one bank at the widest
/// configuration holding the whole depth when that takes fewest blocks (no multiplexer after
/// the blocks), else banks of decreasing depth — the deepest configuration not deeper than
/// the words left, the last words in LUTs when at most `LUT_TAIL` remain — so a ROM's
/// power-of-two padding no longer costs blocks: the teapot's 6,320 triangles of 124 bits are
/// 4,096 words in 4K×4 (31 blocks), 2,048 in 2K×9 (14) and 176 in 1K×18 (7), 52 blocks, where
/// 8K×2 took 62. Each bank's base is a multiple of its depth, so its select is a compare of the
/// address's top bits.
pub fn banks(words: usize, width: u32) -> Vec<Bank> {
    let depth = crate::scene::rom::rom_depth(words);
    let whole = config(depth).map(|(w, _)| vec![Bank { base: 0, abits: depth.trailing_zeros(), w }]);
    let mut split = Vec::new();
    let mut base = 0;
    while base < words {
        let left = words - base;
        if !split.is_empty() && left <= LUT_TAIL {
            split.push(Bank { base, abits: crate::scene::rom::rom_addr_bits(left), w: 0 });
            break;
        }
        let (w, d) = CONFIGS.iter().rev().copied().find(|&(_, d)| d <= left).unwrap_or(CONFIGS[0]);
        split.push(Bank { base, abits: d.trailing_zeros(), w });
        base += d;
    }
    let cost = |v: &Vec<Bank>| v.iter().map(|b| b.blocks(width)).sum::<usize>();
    match whole {
        Some(whole) if cost(&whole) <= cost(&split) => whole,
        _ => split,
    }
}

/// The block ROM module `m` (`cores::brom::brom_module`) as DP16KDs (banks of them, `banks`,
/// with a one-hot multiplexer after the blocks' output registers), and a fabric register after
/// them when it reads in three clocks, or None when it stays as yosys infers it. `generated`
/// is its printed Verilog; its port list is kept.
pub fn dp16kd_rom(generated: &str, m: &Module) -> Option<String> {
    let rom = m.roms.first()?;
    if rom.words.len() < MIN_WORDS {
        return None;
    }
    let layout = banks(rom.words.len(), rom.width);
    let abits = crate::scene::rom::rom_addr_bits(rom.words.len());
    let end = generated.find("\n);\n")? + 4;
    let mut v = String::from(&generated[..end]);
    v.push_str("\n  // DP16KD blocks with their output register (fxrt synth --family ecp5, flow::ecp5_bram).\n");
    // A two-port ROM (`brom_module_ports`) reads its second address on the blocks' port B.
    let ports: &[(&str, &str, &str)] = &[("", "addr", "data"), ("_b", "addr_b", "data_b")][..m.outputs.len()];
    let two = ports.len() == 2;
    let one = layout.len() == 1;
    let zeros = |pin: &str, n| (0..n).map(|i| format!(".{pin}{i}(1'b0)")).collect::<Vec<_>>().join(", ");
    for (k, bank) in layout.iter().enumerate() {
        let tag = if one { String::new() } else { k.to_string() };
        let words_of_bank: Vec<u128> = rom.words.iter().copied().skip(bank.base).take(1 << bank.abits).collect();
        if bank.w == 0 {
            // The tail in LUTs, read through two registers like a block with its output register.
            let _ = writeln!(
                v,
                "  (* rom_style = \"logic\" *) reg [{}:0] tail{k} [0:{}];",
                rom.width - 1,
                (1usize << bank.abits) - 1
            );
            v.push_str("  initial begin\n");
            for a in 0..1usize << bank.abits {
                let word = words_of_bank.get(a).copied().unwrap_or(0);
                let _ = writeln!(v, "    tail{k}[{a}] = {}'h{word:x};", rom.width);
            }
            v.push_str("  end\n");
            for (x, addr, _) in ports {
                let _ = writeln!(
                    v,
                    "  reg [{w1}:0] dout{k}{x}_1 = {w}'h0, dout{k}{x} = {w}'h0;\n  \
                     always @(posedge clk) begin dout{k}{x}_1 <= tail{k}[{addr}[{a1}:0]]; dout{k}{x} <= dout{k}{x}_1; end",
                    w1 = rom.width - 1,
                    w = rom.width,
                    a1 = bank.abits - 1
                );
            }
        } else {
            let w = bank.w;
            let cfg_depth = CONFIGS.iter().find(|c| c.0 == w).expect("a DP16KD width").1;
            let shift = (16384 / cfg_depth).trailing_zeros();
            let blocks = bank.blocks(rom.width);
            let bank_abits = bank.abits;
            let address = |pin: &str, addr: &str| -> String {
                (0..14u32)
                    .map(|p| match p.checked_sub(shift) {
                        Some(i) if i < bank_abits => format!(".{pin}{p}({addr}[{i}])"),
                        _ => format!(".{pin}{p}(1'b0)"),
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            for (x, _, _) in ports {
                let _ = writeln!(v, "  wire [{}:0] dout{tag}{x};", blocks as u32 * w - 1);
            }
            let (wb, regb) = if two { (w, "OUTREG") } else { (18, "NOREG") };
            for j in 0..blocks as u32 {
                let _ = writeln!(v, "  DP16KD #(");
                for (i, init) in initvals(&words_of_bank, j * w, w).iter().enumerate() {
                    let _ = writeln!(v, "    .INITVAL_{i:02X}(320'h{init}),");
                }
                let label = if one { format!("u_bram{j}") } else { format!("u_bank{k}_bram{j}") };
                let _ = writeln!(
                    v,
                    "    .DATA_WIDTH_A({w}), .DATA_WIDTH_B({wb}), .REGMODE_A(\"OUTREG\"), .REGMODE_B(\"{regb}\"),\n    \
                     .RESETMODE(\"SYNC\"), .ASYNC_RESET_RELEASE(\"SYNC\"), .CSDECODE_A(\"0b000\"), .CSDECODE_B(\"0b000\"),\n    \
                     .WRITEMODE_A(\"NORMAL\"), .WRITEMODE_B(\"NORMAL\"), .GSR(\"DISABLED\")\n  ) {label} ("
                );
                let _ = writeln!(v, "    {},", address("ADA", "addr"));
                let _ = writeln!(v, "    {},", zeros("DIA", 18));
                let _ = writeln!(v, "    {},", zeros("DIB", 18));
                let dout: Vec<String> = (0..w).map(|i| format!(".DOA{i}(dout{tag}[{}])", j * w + i)).collect();
                let _ = writeln!(v, "    {},", dout.join(", "));
                v.push_str("    .CLKA(clk), .CEA(1'b1), .OCEA(1'b1), .WEA(1'b0), .RSTA(1'b0), .CSA0(1'b0), .CSA1(1'b0), .CSA2(1'b0),\n");
                if two {
                    let _ = writeln!(v, "    {},", address("ADB", "addr_b"));
                    let dout: Vec<String> = (0..w).map(|i| format!(".DOB{i}(dout{tag}_b[{}])", j * w + i)).collect();
                    let _ = writeln!(v, "    {},", dout.join(", "));
                    v.push_str("    .CLKB(clk), .CEB(1'b1), .OCEB(1'b1), .WEB(1'b0), .RSTB(1'b0), .CSB0(1'b0), .CSB1(1'b0), .CSB2(1'b0)\n");
                } else {
                    let _ = writeln!(v, "    {},", zeros("ADB", 14));
                    v.push_str("    .CLKB(1'b0), .CEB(1'b0), .OCEB(1'b0), .WEB(1'b0), .RSTB(1'b0), .CSB0(1'b0), .CSB1(1'b0), .CSB2(1'b0)\n");
                }
                v.push_str("  );\n");
            }
        }
    }
    let cycles = crate::cores::brom::brom_cycles(m);
    // A fabric register of the word's width named `name`, loading `from`; its name.
    let word_reg = |v: &mut String, name: &str, from: &str| {
        let _ = writeln!(
            v,
            "  reg [{}:0] {name} = {}'h0;\n  always @(posedge clk) {name} <= {from};",
            rom.width - 1,
            rom.width
        );
        name.to_string()
    };
    // With four clocks, each bank's word is registered in the fabric before the multiplexer
    // (the placer puts the register by its blocks), and again after it.
    let bank_regs = cycles == 4;
    for (x, addr, out) in ports {
        let word = if one {
            format!("dout{x}[{}:0]", rom.width - 1)
        } else {
            // Each bank's select: the address's top bits are its base's, registered to meet the
            // words leaving the blocks' output registers (and the banks' fabric registers).
            let mut terms = Vec::new();
            for (k, bank) in layout.iter().enumerate() {
                let prefix = bank.base >> bank.abits;
                let (last, extra) = if bank_regs {
                    (format!("sel{k}{x}_2"), format!(" sel{k}{x}_2 <= sel{k}{x}_1;"))
                } else {
                    (format!("sel{k}{x}_1"), String::new())
                };
                let regs = if bank_regs { format!("sel{k}{x}_1 = 1'b0, sel{k}{x}_2") } else { format!("sel{k}{x}_1") };
                let _ = writeln!(
                    v,
                    "  reg {regs} = 1'b0, sel{k}{x} = 1'b0;\n  \
                     always @(posedge clk) begin sel{k}{x}_1 <= {addr}[{}:{}] == {}'d{prefix};{extra} sel{k}{x} <= {last}; end",
                    abits - 1,
                    bank.abits,
                    abits - bank.abits
                );
                let dout = if bank_regs {
                    word_reg(&mut v, &format!("dout{k}{x}_p"), &format!("dout{k}{x}[{}:0]", rom.width - 1))
                } else {
                    format!("dout{k}{x}[{}:0]", rom.width - 1)
                };
                terms.push(format!("({{{}{{sel{k}{x}}}}} & {dout})", rom.width));
            }
            let _ = writeln!(v, "  wire [{}:0] word{x} = {};", rom.width - 1, terms.join(" | "));
            format!("word{x}")
        };
        let word = if bank_regs && one { word_reg(&mut v, &format!("dout{x}_p"), &word) } else { word };
        if cycles >= 3 {
            // The last clock: a fabric register after the block's output register.
            let q = word_reg(&mut v, &format!("dout{x}_q"), &word);
            let _ = writeln!(v, "  assign {out} = {q};");
        } else {
            let _ = writeln!(v, "  assign {out} = {word};");
        }
    }
    v.push_str("endmodule\n");
    Some(v)
}

/// The block RAM module `m` (`cores::brom::bram_module`, `fxrt_bram_…`) as DP16KDs: port A
/// writes, port B reads with its output register (the module's second clock), or None when it
/// stays as yosys infers it (too small or too deep). `generated` is its printed Verilog.
pub fn dp16kd_ram(generated: &str, m: &Module) -> Option<String> {
    let ram = m.roms.first()?;
    let depth = crate::scene::rom::rom_depth(ram.words.len());
    if ram.words.len() < MIN_WORDS {
        return None;
    }
    let (w, cfg_depth) = config(depth)?;
    let abits = crate::scene::rom::rom_addr_bits(ram.words.len());
    let shift = (16384 / cfg_depth).trailing_zeros();
    let end = generated.find("\n);\n")? + 4;
    let mut v = String::from(&generated[..end]);
    v.push_str("\n  // DP16KD blocks: port A writes, port B reads with its output register (flow::ecp5_bram).\n");
    let blocks = ram.width.div_ceil(w);
    let pad = blocks * w - ram.width;
    let din = if pad == 0 { "wdata".to_string() } else { format!("{{{pad}'h0, wdata}}") };
    let _ = writeln!(v, "  wire [{}:0] din = {din};", blocks * w - 1);
    let _ = writeln!(v, "  wire [{}:0] dout;", blocks * w - 1);
    // In the 18-bit configuration the two lowest address pins of a write port are its byte
    // enables (yosys's brams_map_16kd.v does the same).
    let address = |pin: &str, addr: &str, write: bool| -> String {
        (0..14u32)
            .map(|p| match p.checked_sub(shift) {
                Some(i) if i < abits => format!(".{pin}{p}({addr}[{i}])"),
                _ if write && w == 18 && p < 2 => format!(".{pin}{p}(1'b1)"),
                _ => format!(".{pin}{p}(1'b0)"),
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    for j in 0..blocks {
        let _ = writeln!(
            v,
            "  DP16KD #(\n    .DATA_WIDTH_A({w}), .DATA_WIDTH_B({w}), .REGMODE_A(\"NOREG\"), .REGMODE_B(\"OUTREG\"),\n    \
             .RESETMODE(\"SYNC\"), .ASYNC_RESET_RELEASE(\"SYNC\"), .CSDECODE_A(\"0b000\"), .CSDECODE_B(\"0b000\"),\n    \
             .WRITEMODE_A(\"NORMAL\"), .WRITEMODE_B(\"NORMAL\"), .GSR(\"DISABLED\")\n  ) u_bram{j} ("
        );
        let _ = writeln!(v, "    {},", address("ADA", "waddr", true));
        let din: Vec<String> = (0..18)
            .map(|i| if i < w { format!(".DIA{i}(din[{}])", j * w + i) } else { format!(".DIA{i}(1'b0)") })
            .collect();
        let _ = writeln!(v, "    {},", din.join(", "));
        v.push_str(
            "    .CLKA(clk), .CEA(1'b1), .OCEA(1'b1), .WEA(we), .RSTA(1'b0), .CSA0(1'b0), .CSA1(1'b0), .CSA2(1'b0),\n",
        );
        let _ = writeln!(v, "    {},", address("ADB", "raddr", false));
        let zeros: Vec<String> = (0..18).map(|i| format!(".DIB{i}(1'b0)")).collect();
        let _ = writeln!(v, "    {},", zeros.join(", "));
        let dout: Vec<String> = (0..w).map(|i| format!(".DOB{i}(dout[{}])", j * w + i)).collect();
        let _ = writeln!(v, "    {},", dout.join(", "));
        v.push_str(
            "    .CLKB(clk), .CEB(1'b1), .OCEB(1'b1), .WEB(1'b0), .RSTB(1'b0), .CSB0(1'b0), .CSB1(1'b0), .CSB2(1'b0)\n",
        );
        v.push_str("  );\n");
    }
    let _ = writeln!(v, "  assign data = dout[{}:0];", ram.width - 1);
    v.push_str("endmodule\n");
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cores::brom::brom_module;
    use crate::rtl::emit;

    #[test]
    fn widest_configuration_without_a_multiplexer() {
        assert_eq!(config(1000), Some((18, 1024)));
        assert_eq!(config(4379), Some((2, 8192)));
        assert_eq!(config(8192), Some((2, 8192)));
        assert_eq!(config(8193), Some((1, 16384)));
        assert_eq!(config(16385), None);
    }

    /// Banks cover every word once, in decreasing depth, each base a multiple of its depth;
    /// a split is taken only when it saves blocks (the teapot's triangle and node ROMs).
    #[test]
    fn banks_cover_the_words_and_save_blocks() {
        let blocks = |v: &[Bank], w| v.iter().map(|b| b.blocks(w)).sum::<usize>();
        assert_eq!(banks(6320, 124).iter().map(|b| (b.base, b.w)).collect::<Vec<_>>(), [(0, 4), (4096, 9), (6144, 18)]);
        assert_eq!(blocks(&banks(6320, 124), 124), 31 + 14 + 7);
        assert_eq!(blocks(&banks(4450, 76), 76), 19 + 5, "not 38 of 8K×2");
        assert_eq!(banks(6240, 76).last(), Some(&Bank { base: 6144, abits: 7, w: 0 }), "96 words in LUTs");
        assert_eq!(banks(8192, 76), [Bank { base: 0, abits: 13, w: 2 }], "a full depth stays one bank");
        assert_eq!(banks(3000, 20), [Bank { base: 0, abits: 12, w: 4 }], "no saving, no split");
        for words in [128, 1000, 1025, 3000, 4097, 5000, 6240, 6320, 12_345, 16_384, 40_000] {
            let v = banks(words, 76);
            let mut next = 0;
            for b in &v {
                assert_eq!(b.base, next, "{words}: {v:?}");
                assert_eq!(b.base % (1 << b.abits), 0, "{words}: {v:?}");
                next += 1 << b.abits;
            }
            assert!(next >= words && (v.len() == 1 || next - (1 << v.last().unwrap().abits) < words), "{words}: {v:?}");
            let whole = config(crate::scene::rom::rom_depth(words)).map(|(w, _)| 76usize.div_ceil(w as usize));
            assert!(whole.is_none_or(|whole| blocks(&v, 76) <= whole), "{words}: {v:?}");
        }
    }

    /// The substitute keeps the ports, uses one block per w bits, the output register, and
    /// no fabric register.
    #[test]
    fn a_rom_becomes_dp16kds_with_their_output_register() {
        let words: Vec<u128> = (0..3000u128).map(|k| k * 2_654_435_761 % (1 << 20)).collect();
        let m = brom_module("t", 20, words, 2);
        let files = emit::design_files(&m, "v");
        let (_, text) = files.iter().find(|(n, _)| n == "fxrt_brom_t.v").expect("the module's file");
        let v = dp16kd_rom(text, &m).expect("a DP16KD ROM");
        assert!(v.starts_with(&text[..text.find("\n);\n").unwrap()]));
        assert_eq!(v.matches("DP16KD #(").count(), 5, "4K×4 blocks for 20 bits");
        assert!(v.contains(".DATA_WIDTH_A(4)") && v.contains(".REGMODE_A(\"OUTREG\")"));
        assert!(v.contains(".ADA2(addr[0])") && v.contains(".ADA13(addr[11])") && v.contains(".ADA1(1'b0)"));
        assert!(!v.contains("always") && !v.contains("readmem"));
        let m3 = brom_module("t", 20, (0..3000).collect(), 3);
        let files = emit::design_files(&m3, "v");
        let v3 = dp16kd_rom(&files.iter().find(|(n, _)| n == "fxrt_brom_t.v").unwrap().1, &m3).unwrap();
        assert!(v3.contains("always @(posedge clk) dout_q <= dout[19:0];") && v3.contains("assign data = dout_q;"));
        // Too small: left to yosys.
        let small = brom_module("s", 8, vec![1; 100], 2);
        let files = emit::design_files(&small, "v");
        assert!(dp16kd_rom(&files.iter().find(|(n, _)| n == "fxrt_brom_s.v").unwrap().1, &small).is_none());
    }

    /// A RAM writes on port A and reads on port B with its output register; in the 18-bit
    /// configuration the write port's byte enables (the two lowest address pins) are on.
    #[test]
    fn a_ram_becomes_dp16kds_written_on_a_read_on_b() {
        use crate::cores::brom::bram_module;
        for (words, width, blocks, wide) in [(2048usize, 77u32, 9usize, false), (1024, 36, 2, true)] {
            let m = bram_module("s", width, words);
            let files = emit::design_files(&m, "v");
            let v = dp16kd_ram(&files.iter().find(|(n, _)| n == "fxrt_bram_s.v").unwrap().1, &m).unwrap();
            assert_eq!(v.matches("DP16KD #(").count(), blocks, "{words}×{width}");
            assert!(v.contains(".REGMODE_B(\"OUTREG\")") && v.contains(".WEA(we)") && v.contains(".DOB0(dout[0])"));
            assert!(v.contains("assign data = dout[") && !v.contains("always") && !v.contains("readmem"));
            assert_eq!(v.contains(".ADA0(1'b1), .ADA1(1'b1)"), wide, "{words}×{width}");
            assert!(v.contains(&format!(".ADB13(raddr[{}])", words.trailing_zeros() - 1)));
        }
        assert!(dp16kd_ram("", &bram_module("t", 8, 64)).is_none(), "small RAMs stay LUTs");
    }

    /// Bit k = a·w + b of a narrow block skips the ninth bits of each 18-bit row.
    #[test]
    fn init_layout() {
        let mut words = vec![0u128; 16384];
        words[8] = 1; // k = 8 at width 1: row 0, column 9
        words[16] = 1; // k = 16: row 1, column 0 → bit 20
        let iv = initvals(&words, 0, 1);
        assert!(iv[0].ends_with(&format!("{:020x}", (1u128 << 20) | (1 << 9))), "{}", iv[0]);
        let mut words = vec![0u128; 1024];
        words[1] = 1 << 17; // width 18: word 1 bit 17 → row 1, column 17 → bit 37
        let iv = initvals(&words, 0, 18);
        assert!(iv[0].ends_with(&format!("{:020x}", 1u128 << 37)), "{}", iv[0]);
    }
}
