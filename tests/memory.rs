//! The AXI read master and two caches in every HDL simulator: the transcript of a Rust-simulator
//! run against the memory model (`verify::memory_tests::drive`, with random R pauses and extra
//! delays) replayed in GHDL, Icarus (Verilog-2005 and SystemVerilog rules) and Verilator, every
//! output equal on every clock. Each simulator not installed is reported as skipped.

use fxrt::verify::memory::MemoryTiming;
use fxrt::verify::memory_tests::{drive, harness};
use fxrt::verify::simulators::Simulator;
use fxrt::verify::testbench::{bench_files, record};
use std::io::Write;

#[test]
fn caches_and_master_agree_in_every_simulator() {
    let m = harness(4);
    let timing = MemoryTiming { latency: 12, outstanding: 3, extra_delay: 9, pause_in_256: 60, seed: 77 };
    let d = drive(&m, timing, 5_000, 11, None);
    assert!(d.hits > 100 && d.bursts > 50, "{} hits, {} bursts", d.hits, d.bursts);
    let clocks = d.stimuli.len() as u64;
    let t = record(&m, d.stimuli);
    let mut ran = 0;
    for sim in Simulator::ALL.into_iter().chain([Simulator::IverilogSv]) {
        if !sim.available() {
            let _ = writeln!(std::io::stderr().lock(), "skipped: {} is not installed", sim.name());
            continue;
        }
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("memory_{}", sim.name()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for (file, text) in bench_files(&m, &t, sim) {
            std::fs::write(dir.join(file), text).unwrap();
        }
        let (passed, failed) = sim.run(&dir, &m).unwrap_or_else(|e| panic!("{e}"));
        eprintln!("{}: {passed} passed, {failed} failed", sim.name());
        assert_eq!((passed, failed), (clocks, 0), "{}", sim.name());
        ran += 1;
    }
    eprintln!("{ran} HDL simulators ran");
}
