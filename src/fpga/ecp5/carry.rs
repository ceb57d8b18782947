//! The divider's add-or-subtract steps (`cores::divider::addsub_core`) as ECP5 CCU2C carry
//! chains with the choice between adding and subtracting inside each cell, for place and
//! route only.
//!
//! Yosys maps `a + (b ^ sub…sub) + sub` to a LUT per bit for the XOR in front of a CCU2C
//! chain whose cells compute only a ⊕ b: the sign register then drives the LUTs, whose
//! outputs are routed into the chain (a non-restoring stage measured 194 MHz, no faster than
//! a restoring one). A CCU2C half computes its propagate signal with a LUT4 of four inputs
//! (A, B, C, D) and its generate with a LUT2 of A and B, the LUT4's first four INIT bits.
//! With D = 1 and the step's `sub` on C, the propagate is a ⊕ b ⊕ sub and the generate a:
//! the inversion costs nothing and the sign register drives the chain's cells directly
//! (docs/TIMING.md: 242 MHz for a bare stage chain against 194). The carry-in `sub` enters
//! through an extra bottom bit with A = B = sub (it generates sub, its sum is unused), not
//! through CIN, which nextpnr would feed through a cell of its own; the top bit's LUT
//! computes the inverted sum, so `ge` (the result is not negative) needs no LUT after the
//! chain. The cell semantics are yosys's simulation model (`+/ecp5/cells_sim.v`, CCU2C), and
//! `tests/ecp5.rs` proves the substitute equal to the generated module with it.

use std::fmt::Write;

/// INIT of a chain half: LUT4 (D = 1) a ⊕ b ⊕ c, LUT2 (generate) a.
const INIT_ADD: &str = "16'b1001_0110_1010_1010";
/// The top half: the inverted sum (its carry-out is not used).
const INIT_TOP: &str = "16'b0110_1001_1010_1010";

/// The operand width of a step module file name (`fxrt_addsub_w35.v` → 35).
pub fn addsub_width_of(file: &str) -> Option<u32> {
    file.strip_prefix(crate::cores::divider::ADDSUB_PREFIX)?.strip_suffix(".v")?.parse().ok().filter(|w| *w >= 2)
}

/// `generated`, the step module's Verilog, with its body replaced by a CCU2C chain of `w`
/// sum bits and the carry-in bit. The port list (everything up to the line `);`) is kept.
pub fn ccu2c_addsub(generated: &str, w: u32) -> Option<String> {
    let end = generated.find("\n);\n")? + 4;
    let mut v = String::from(&generated[..end]);
    v.push_str(
        "\n  // The step as one ECP5 carry chain, the add-or-subtract in each cell's LUT (fxrt synth --family ecp5).\n",
    );
    // Chain bit 0 brings in the carry; bit i + 1 is sum bit i.
    let bits = w + 1;
    let cells = bits.div_ceil(2);
    let _ = writeln!(v, "  wire [{cells}:0] carry;\n  wire [{}:0] s;\n  assign carry[0] = 1'b0;", 2 * cells - 1);
    let input = |j: u32, port: &str| -> String {
        match j {
            0 => "sub[0]".into(),
            j if j <= w => format!("{port}[{}]", j - 1),
            _ => "1'b0".into(),
        }
    };
    for c in 0..cells {
        let (j0, j1) = (2 * c, 2 * c + 1);
        let init = |j: u32| if j == w { INIT_TOP } else { INIT_ADD };
        let c_in = |j: u32| if j == 0 || j > w { "1'b0" } else { "sub[0]" };
        let _ = writeln!(
            v,
            "  CCU2C #(.INIT0({}), .INIT1({}), .INJECT1_0(\"NO\"), .INJECT1_1(\"NO\")) u_cell{c} (\n    .CIN(carry[{c}]), .COUT(carry[{}]),\n    .A0({}), .B0({}), .C0({}), .D0(1'b1), .S0(s[{j0}]),\n    .A1({}), .B1({}), .C1({}), .D1(1'b1), .S1(s[{j1}])\n  );",
            init(j0),
            init(j1),
            c + 1,
            input(j0, "a"),
            input(j0, "b"),
            c_in(j0),
            input(j1, "a"),
            input(j1, "b"),
            c_in(j1),
        );
    }
    let _ = writeln!(v, "  assign diff = s[{}:1];\n  assign ge = s[{w}];\nendmodule", w - 1);
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cores::divider::addsub_core;
    use crate::rtl::emit;

    /// The substitute keeps the generated ports, has no arithmetic operator left, and uses
    /// the inverted LUT only for the top bit.
    #[test]
    fn chain_keeps_ports_and_inverts_only_the_top_bit() {
        for w in [2, 5, 8, 35] {
            let m = addsub_core(w);
            let files = emit::design_files(&m, "v");
            let (name, text) = files.iter().find(|(n, _)| addsub_width_of(n).is_some()).expect("the module's file");
            assert_eq!(addsub_width_of(name), Some(w));
            let v = ccu2c_addsub(text, w).expect("a port list");
            let header = &text[..text.find("\n);\n").unwrap()];
            assert!(v.starts_with(header), "{v}");
            assert!(!v.contains(" + ") && !v.contains(" ^ "), "no fabric arithmetic left: {v}");
            assert_eq!(v.matches("CCU2C #").count() as u32, (w + 1).div_ceil(2));
            assert_eq!(v.matches(INIT_TOP).count(), 1, "{v}");
            assert!(v.contains(&format!(".A0(a[{}])", 1)) || w < 2);
            assert!(v.contains(&format!("assign ge = s[{w}];")));
        }
    }
}
