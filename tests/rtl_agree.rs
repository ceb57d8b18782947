//! One meaning per operator: random netlists (every operator, signed and unsigned, `case`
//! with signed selectors, delay lines, memories, feedback through registers) run in the cycle
//! simulator and the batched simulator, and a sample of them in GHDL, Icarus and Verilator,
//! must agree bit for bit on every output of every cycle.

use fxrt::rtl::random::{Shape, agree, random_inputs, random_module, sim_vs_batch};
use fxrt::rtl::sim::Sim;
use fxrt::rtl::{Module, Ty};
use fxrt::verify::simulators::Simulator;
use fxrt::verify::testbench::{Stimulus, record, replay};
use std::io::Write;

/// The divergence found in issue 10: a register `r: s(2)` with next value
/// `case(r, [0 → −1, 3 → 1], default 0)`. Arm patterns are bit patterns of the selector, so
/// r = −1 (bits 11) takes the arm 3: −1, 1, 0, −1, 1, 0, …
#[test]
fn signed_case_selector_matches_arm_bit_patterns() {
    let mut m = Module::new("signed_case");
    let r = m.reg("r", Ty::s(2), Some(-1));
    let minus1 = m.konst("minus1", Ty::s(2), -1);
    let one = m.konst("one", Ty::s(2), 1);
    let zero = m.konst("zero", Ty::s(2), 0);
    let next = m.case("next", r, &[(0, minus1), (3, one)], zero);
    m.connect(r, next, None);
    m.output("r", r);
    let mut sim = Sim::new(&m);
    let r_out = m.handle(m.outputs[0].1);
    let seen: Vec<i128> = (0..6)
        .map(|_| {
            sim.tick();
            sim.get(r_out)
        })
        .collect();
    assert_eq!(seen, [1, 0, -1, 1, 0, -1]);
    for batch in [1, 4, 256] {
        sim_vs_batch(&m, &vec![vec![]; 40], batch).unwrap_or_else(|e| panic!("batch {batch}: {e}"));
    }
}

#[test]
fn cycle_and_batched_simulators_agree_on_10000_random_netlists() {
    let count: u64 = std::env::var("FXRT_AGREE_NETLISTS").ok().and_then(|s| s.parse().ok()).unwrap_or(10_000);
    let failures = agree(0..count, &|| {});
    assert!(failures.is_empty(), "{} of {count} random netlists disagree; first: {}", failures.len(), failures[0]);
}

#[test]
fn hdl_simulators_agree_on_sampled_random_netlists() {
    let seeds: Vec<u64> = (0..6).map(|k| 1_000_003 * k + 17).collect();
    let mut ran = 0;
    for sim in Simulator::ALL {
        if !sim.available() {
            let _ = writeln!(std::io::stderr().lock(), "skipped: {} is not installed", sim.name());
            continue;
        }
        for &seed in &seeds {
            let m = random_module(seed, Shape { max_width: 128, nodes: 40 });
            let stimuli: Vec<Stimulus> = random_inputs(&m, seed, 120)
                .into_iter()
                .enumerate()
                .map(|(c, inputs)| Stimulus { reset: c == 5, inputs })
                .collect();
            let t = record(&m, stimuli);
            let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("agree_{}_{seed}", sim.name()));
            let (passed, failed) =
                replay(&m, &t, sim, &dir, &[]).unwrap_or_else(|e| panic!("{} seed {seed}: {e}", sim.name()));
            assert_eq!((passed, failed), (120, 0), "{} seed {seed}: see {}", sim.name(), dir.display());
            ran += 1;
        }
    }
    eprintln!("{ran} HDL runs of random netlists agreed with the Rust simulator");
}
