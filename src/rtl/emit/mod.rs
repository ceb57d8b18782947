//! The two printers. `walk::print` is the one skeleton: it walks a module, matching every
//! definition exhaustively, and asks a `walk::Printer` (`vhdl::Vhdl`, `verilog::Verilog`, the
//! same function list) how each part is spelled; both write through one `CodeWriter`. Neither
//! computes a width: every type comes from the netlist.

pub mod verilog;
pub mod vhdl;
pub mod walk;
pub mod writer;

pub use walk::{Printer, print};
pub use writer::CodeWriter;

use crate::bits::rom_depth;
use crate::rtl::width::BinOp;

/// The operator as Verilog (and C) spell it.
pub fn symbol(op: BinOp) -> &'static str {
    match op {
        BinOp::Add => "+",
        BinOp::Sub => "-",
        BinOp::And => "&",
        BinOp::Or => "|",
        BinOp::Xor => "^",
        BinOp::Mul => "*",
        BinOp::Eq => "==",
        BinOp::Ne => "!=",
        BinOp::Lt => "<",
        BinOp::Le => "<=",
    }
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
