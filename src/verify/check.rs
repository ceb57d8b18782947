//! `fxrt test`: the intersection pipeline against the golden model, in the Rust simulator or
//! in an HDL simulator through a generated self-checking testbench.

use super::simulators::{RunResult, Simulator};
use super::testbench::{Stimulus, bench_files, record};
use super::vectors::Vector;
use crate::cores::intersect::{IntersectParams, expected_outputs, intersect_core, pack_inputs};
use crate::error::{Error, Result};
use crate::rtl::batch::BatchSim;
use crate::rtl::netlist::Module;
use crate::rtl::sim::Sim;
use std::path::Path;

/// Counts of vectors (Rust) or clock cycles (HDL) that matched and did not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Outcome {
    pub passed: u64,
    pub failed: u64,
}

/// Inputs of every vector, then `latency` idle cycles to drain the pipeline.
fn stimuli(module: &Module, latency: u32, vectors: &[Vector]) -> Vec<Stimulus> {
    let width = module.inputs.len();
    let mut v: Vec<Stimulus> = vectors
        .iter()
        .enumerate()
        .map(|(i, x)| Stimulus { reset: false, inputs: pack_inputs(tag_of(module, i), &x.tri, &x.ray) })
        .collect();
    v.extend((0..latency).map(|_| Stimulus { reset: false, inputs: vec![0; width] }));
    v
}

/// Vector numbers wrap at the tag width.
fn tag_of(module: &Module, i: usize) -> u64 {
    let w = module.sig(module.inputs[1]).ty.width;
    (i as u64) & if w >= 64 { u64::MAX } else { (1u64 << w) - 1 }
}

/// Which Rust engine simulates the pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Engine {
    /// `Sim`: one clock edge at a time (any design).
    Cycle,
    /// `BatchSim`: 1,024 cycles per pass (feed-forward designs; the same results).
    Batch,
}

/// Runs the pipeline in the Rust simulator and compares every output with the golden model.
pub fn run_rust(p: &IntersectParams, vectors: &[Vector]) -> Outcome {
    run_rust_with(Engine::Batch, p, vectors).0
}

/// Also returns the seconds of the simulation loop alone (with the comparison): inputs and
/// expected outputs are prepared first, as the Verilator harness reads its file first.
pub fn run_rust_with(engine: Engine, p: &IntersectParams, vectors: &[Vector]) -> (Outcome, f64) {
    let module = intersect_core(p);
    let stim = stimuli(&module, p.latency(), vectors);
    let expected: Vec<[i128; 6]> =
        vectors.iter().enumerate().map(|(k, v)| expected_outputs(tag_of(&module, k), v.expected)).collect();
    let lat = p.latency() as usize;
    let mut o = Outcome { passed: 0, failed: 0 };
    // Outputs after clock c belong to vector c + 1 − latency.
    let mut judge = |c: usize, outs: &[i128]| {
        if c + 1 >= lat && c + 1 - lat < vectors.len() {
            if outs == expected[c + 1 - lat].as_slice() { o.passed += 1 } else { o.failed += 1 }
        }
    };
    let nout = module.outputs.len();
    let start = std::time::Instant::now();
    // 256 cycles per pass keeps every signal's lanes in the L2 cache.
    match (engine, BatchSim::new(&module, 256)) {
        (Engine::Batch, Some(mut b)) => {
            let mut row = vec![0i128; nout];
            b.run(
                stim.len(),
                |c, k| stim[c].inputs[k],
                |c, k, v| {
                    row[k] = v;
                    if k + 1 == nout {
                        judge(c, &row);
                    }
                },
            );
        }
        _ => {
            let mut sim = Sim::new(&module);
            let ins: Vec<_> = module.inputs.iter().map(|&i| module.handle(i)).collect();
            let outs: Vec<_> = module.outputs.iter().map(|(_, i)| module.handle(*i)).collect();
            let mut row = vec![0i128; nout];
            for (c, st) in stim.iter().enumerate() {
                for (s, v) in ins.iter().zip(&st.inputs) {
                    sim.set(*s, *v);
                }
                sim.tick();
                for (r, s) in row.iter_mut().zip(&outs) {
                    *r = sim.get(*s);
                }
                judge(c, &row);
            }
        }
    }
    (o, start.elapsed().as_secs_f64())
}

/// Writes the HDL, a testbench and its vectors into `dir` and runs `sim` on them. The
/// expected outputs are the Rust simulator's, which must first agree with the golden model.
pub fn run_hdl(sim_kind: Simulator, p: &IntersectParams, vectors: &[Vector], dir: &Path) -> Result<Outcome> {
    let rust = run_rust(p, vectors);
    if rust.failed > 0 {
        return Err(Error::new(
            "rust",
            format!(
                "the Rust simulation disagrees with the golden model on {} of {} vectors",
                rust.failed,
                vectors.len()
            ),
        ));
    }
    if !sim_kind.available() {
        return Err(Error::new(sim_kind.name(), "is not installed (scripts/install-deps.sh installs it)"));
    }
    let module = intersect_core(p);
    let r = simulate_hdl(sim_kind, &module, p.latency(), vectors, dir)?;
    let (passed, failed) = (r.passed, r.failed);
    Ok(Outcome { passed, failed })
}

/// Cycles per second of each simulator on the same vectors (`fxrt bench sim`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct SimSpeed {
    pub simulator: &'static str,
    pub cycles: u64,
    pub seconds: f64,
    pub cycles_per_second: f64,
    pub all_passed: bool,
}

/// GHDL runs only the first `ghdl_vectors` of the vectors: it is three orders of magnitude
/// slower, and a cycles-per-second figure needs no more.
pub fn bench_sims(p: &IntersectParams, vectors: &[Vector], ghdl_vectors: usize, dir: &Path) -> Result<Vec<SimSpeed>> {
    let cycles = (vectors.len() + p.latency() as usize) as u64;
    let mut out = Vec::new();
    for (name, engine) in [("rust", Engine::Batch), ("rust-cycle", Engine::Cycle)] {
        let (rust, secs) = run_rust_with(engine, p, vectors);
        out.push(SimSpeed {
            simulator: name,
            cycles,
            seconds: secs,
            cycles_per_second: cycles as f64 / secs,
            all_passed: rust.failed == 0 && rust.passed == vectors.len() as u64,
        });
    }
    let module = intersect_core(p);
    for sim in [Simulator::Verilator, Simulator::Ghdl] {
        if !sim.available() {
            continue;
        }
        let vectors = if sim == Simulator::Ghdl { &vectors[..ghdl_vectors.min(vectors.len())] } else { vectors };
        let cycles = (vectors.len() + p.latency() as usize) as u64;
        let r = simulate_hdl(sim, &module, p.latency(), vectors, &dir.join(sim.name()))?;
        out.push(SimSpeed {
            simulator: sim.name(),
            cycles,
            seconds: r.seconds,
            cycles_per_second: cycles as f64 / r.seconds,
            all_passed: r.failed == 0 && r.passed == cycles,
        });
    }
    Ok(out)
}

/// Records the Rust transcript of `vectors`, writes the design, the testbench and the vectors
/// for `sim` into `dir`, and runs the testbench there.
fn simulate_hdl(sim: Simulator, module: &Module, latency: u32, vectors: &[Vector], dir: &Path) -> Result<RunResult> {
    let transcript = record(module, stimuli(module, latency, vectors));
    let mut files = crate::io::OutputSet::new();
    files.extend(bench_files(module, &transcript, sim).into_iter().map(|(file, text)| (dir.join(file), text)))?;
    files.commit()?;
    sim.run_timed(dir, module).map_err(|e| Error::new(sim.name(), e))
}
