//! The DSP pieces of split multipliers (`cores::mul::dsp18_core`) as ECP5 MULT18X18D
//! primitives with their own registers enabled, for place and route only.
//!
//! Yosys maps an inferred ECP5 multiplier to a MULT18X18D with every register bypassed and
//! leaves the registers around it in the fabric (yosys issue 5917 for the same on Nexus), which
//! stops a registered 18×18 product near 140 MHz; the DSP's input, pipeline and output
//! registers get past 200 (`../shared/docs/ANCHORS.md`). So `fxrt synth --family ecp5`
//! replaces the body of each `fxrt_dsp18_r{k}` module by the primitive with the same k
//! register levels: inputs (A, B), then pipeline and output (k = 3) or output only (k = 2);
//! k = 4 adds a fabric register after the block.
//! The ports and the cycle behaviour are the generated module's, which every simulator checks
//! against the golden model; the instance follows yosys's own `$__MUL18X18` → MULT18X18D
//! map (`share/lattice/dsp_map_18x18.v`: SIGNEDA/SIGNEDB set for signed operands, C unused),
//! with only the register parameters added. No simulation model of MULT18X18D ships with
//! yosys, so the substitution is timed, not simulated (docs/TIMING.md, DECISIONS.md).

use std::fmt::Write;

/// The file name prefix of the DSP piece modules.
pub const DSP_MODULE_PREFIX: &str = "fxrt_dsp18_r";

/// The register levels of a DSP piece module file name (`fxrt_dsp18_r3.v` → 3).
pub fn dsp_regs_of(file: &str) -> Option<u32> {
    file.strip_prefix(DSP_MODULE_PREFIX)?.strip_suffix(".v")?.parse().ok().filter(|k| *k <= 4)
}

/// `generated`, the module's Verilog, with its body replaced by a MULT18X18D with `regs`
/// register levels (the fourth a fabric register after the block). The port list
/// (everything up to the line `);`) is kept as printed.
pub fn mult18x18d(generated: &str, regs: u32) -> Option<String> {
    let end = generated.find("\n);\n")? + 4;
    let clk = |on: bool| if on { "\"CLK0\"" } else { "\"NONE\"" };
    let mut v = String::from(&generated[..end]);
    v.push_str("\n  // The ECP5 DSP block with its own registers (fxrt synth --family ecp5).\n");
    let _ = writeln!(
        v,
        "  MULT18X18D #(\n    .REG_INPUTA_CLK({a}), .REG_INPUTB_CLK({a}), .REG_PIPELINE_CLK({p}), .REG_OUTPUT_CLK({o}),\n    .GSR(\"DISABLED\"), .RESETMODE(\"SYNC\")\n  ) u_mult18 (",
        a = clk(regs >= 1),
        p = clk(regs >= 3),
        o = clk(regs >= 2),
    );
    let bus = |name: &str, port: char, n: u32| {
        (0..n).map(|i| format!(".{port}{i}({name}[{i}])")).collect::<Vec<_>>().join(", ")
    };
    let _ = writeln!(v, "    {},", bus("a", 'A', 18));
    let _ = writeln!(v, "    {},", bus("b", 'B', 18));
    let zeros: Vec<String> = (0..18).map(|i| format!(".C{i}(1'b0)")).collect();
    let _ = writeln!(v, "    {},", zeros.join(", "));
    v.push_str("    .SIGNEDA(1'b1), .SIGNEDB(1'b1), .SOURCEA(1'b0), .SOURCEB(1'b0),\n");
    v.push_str(
        "    .CLK0(clk), .CLK1(1'b0), .CLK2(1'b0), .CLK3(1'b0), .CE0(1'b1), .CE1(1'b0), .CE2(1'b0), .CE3(1'b0),\n",
    );
    v.push_str("    .RST0(1'b0), .RST1(1'b0), .RST2(1'b0), .RST3(1'b0),\n");
    // The fourth level lands the product in the fabric, where the adder tree is.
    let out = if regs >= 4 { "p_dsp" } else { "p" };
    if regs >= 4 {
        v.insert_str(end, "  wire [35:0] p_dsp;\n  reg [35:0] p_land;\n  always @(posedge clk) p_land <= p_dsp;\n  assign p = p_land;\n");
    }
    let _ = writeln!(v, "    {}", bus(out, 'P', 36));
    v.push_str("  );\nendmodule\n");
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cores::mul::dsp18_core;
    use crate::rtl::emit;

    /// The substitute keeps the generated ports and sets exactly the registers the module has.
    #[test]
    fn primitive_keeps_ports_and_register_levels() {
        for regs in 0..=4 {
            let m = dsp18_core(regs);
            let files = emit::design_files(&m, "v");
            let (name, text) = files.iter().find(|(n, _)| dsp_regs_of(n).is_some()).expect("the module's file");
            assert_eq!(dsp_regs_of(name), Some(regs));
            let v = mult18x18d(text, regs).expect("a port list");
            let header = &text[..text.find("\n);\n").unwrap()];
            assert!(v.starts_with(header), "{v}");
            assert_eq!(v.contains("always"), regs == 4, "a fabric register only after a 4-level block: {v}");
            for (param, on) in
                [("REG_INPUTA_CLK", regs >= 1), ("REG_PIPELINE_CLK", regs >= 3), ("REG_OUTPUT_CLK", regs >= 2)]
            {
                let want = format!(".{param}({})", if on { "\"CLK0\"" } else { "\"NONE\"" });
                assert!(v.contains(&want), "{regs}: {want} in {v}");
            }
            let p = if regs == 4 { "p_dsp" } else { "p" };
            assert!(v.contains(&format!(".P35({p}[35])")) && v.contains(".A17(a[17])") && v.contains(".B0(b[0])"));
        }
    }
}
