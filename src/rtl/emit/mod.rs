//! The two printers. Both walk the same netlist with the same function list and match every
//! definition exhaustively; they differ only in syntax. Neither computes a width: every type
//! comes from the netlist.

pub mod verilog;
pub mod vhdl;

/// ROM depth as printed: the next power of two (at least 2, as the address has at least one
/// bit), padded with zero words, so every address of the port is in range (the simulator
/// reads 0 beyond the end too).
pub fn rom_depth(words: usize) -> usize {
    words.next_power_of_two().max(2)
}

/// Bits needed to address a ROM of `words` words.
pub fn rom_addr_bits(words: usize) -> u32 {
    rom_depth(words).trailing_zeros().max(1)
}

/// The bits of `v` as a string of width `w`, most significant first.
pub fn bit_string(v: u128, w: u32) -> String {
    (0..w).rev().map(|b| if (v >> b) & 1 == 1 { '1' } else { '0' }).collect()
}

/// The bits of `v` in hex, ⌈w/4⌉ digits.
pub fn hex_string(v: u128, w: u32) -> String {
    let digits = w.div_ceil(4) as usize;
    format!("{v:0digits$x}")
}

/// The HDL files of a design in one language: one file per module, sub-modules first (the
/// order to compile them in), and for Verilog each module's `$readmemh` memory files after it.
/// `ext` is "vhd" or "v".
pub fn design_files(top: &crate::rtl::Module, ext: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for m in top.hierarchy() {
        if ext == "vhd" {
            out.push((format!("{}.vhd", m.name), vhdl::print(m)));
        } else {
            out.push((format!("{}.v", m.name), verilog::print(m)));
            out.extend(verilog::mem_files(m));
        }
    }
    out
}

/// Whether a file of `design_files` is HDL source (not memory contents).
pub fn is_source(file: &str) -> bool {
    file.ends_with(".v") || file.ends_with(".vhd")
}

#[cfg(test)]
mod tests {
    /// A one-word memory still has a one-bit address, so it is printed with two words.
    #[test]
    fn every_address_is_a_word() {
        for words in [1usize, 2, 3, 4, 5, 1000] {
            assert_eq!(super::rom_depth(words), 1 << super::rom_addr_bits(words), "{words}");
            assert!(super::rom_depth(words) >= words);
        }
    }
}
