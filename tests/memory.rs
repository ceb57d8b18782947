//! The AXI read master and two caches in every HDL simulator: the transcript of a Rust-simulator
//! run against the memory model (`verify::memory_tests::drive_across_a_reset`, with random R
//! pauses and extra delays, a reset and a new image halfway) replayed in GHDL, Icarus (Verilog-2005 and SystemVerilog rules) and Verilator, every
//! output equal on every clock. Each simulator not installed is reported as skipped.

use fxrt::verify::memory::MemoryTiming;
use fxrt::verify::memory_tests::{Shape, drive_across_a_reset, harness};
use fxrt::verify::simulators::Simulator;
use fxrt::verify::testbench::{record, replay};
use std::io::Write;

#[test]
fn caches_and_master_agree_in_every_simulator() {
    let shape = Shape { data_bits: 64, ways: 2, outstanding: 4 };
    let m = harness(shape);
    let timing = MemoryTiming { latency: 12, outstanding: 3, extra_delay: 9, pause_in_256: 60, seed: 77 };
    let d = drive_across_a_reset(&m, shape, timing, 4_000, 11);
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
        let (passed, failed) = replay(&m, &t, sim, &dir, &[]).unwrap_or_else(|e| panic!("{e}"));
        eprintln!("{}: {passed} passed, {failed} failed", sim.name());
        assert_eq!((passed, failed), (clocks, 0), "{}", sim.name());
        ran += 1;
    }
    eprintln!("{ran} HDL simulators ran");
}

/// The memory model as the testbenches have it (`verify::memory_hdl`) against the Rust one: a
/// random master (addresses, burst lengths, RREADY low at times, resets) drives both; every
/// output of the HDL model equals the Rust model's on every clock, in every simulator.
#[test]
fn the_memory_model_is_the_same_in_every_simulator() {
    use fxrt::rtl::Ty;
    use fxrt::rtl::build::Builder;
    use fxrt::verify::memory::{MasterOut, MemoryModel, xorshift32};
    use fxrt::verify::memory_hdl::{MODEL, model_files};
    use fxrt::verify::testbench::{Stimulus, Transcript};
    for (data_bits, timing) in [
        (64, MemoryTiming { latency: 5, outstanding: 3, extra_delay: 7, pause_in_256: 80, seed: 12345 }),
        (128, MemoryTiming { latency: 1, outstanding: 1, extra_delay: 0, pause_in_256: 0, seed: 1 }),
        (32, MemoryTiming { latency: 40, outstanding: 16, extra_delay: 0, pause_in_256: 200, seed: 7 }),
    ] {
        let addr_bits = 16;
        let base = 0x1000u64;
        let image: Vec<u8> = (0..4096u32).map(|k| (k.wrapping_mul(2654435761) >> 11) as u8).collect();
        // A module with the model's ports, for the testbench generator; its design file is
        // replaced by the model's.
        let b = Builder::new(MODEL);
        let ins = [("arvalid", 1), ("araddr", addr_bits), ("arlen", 8), ("rready", 1)]
            .map(|(name, w)| b.input(name, Ty::u(w)));
        let held = b.reg("held", Ty::BIT, Some(0));
        b.next(held, ins[0]);
        for (name, w) in [("arready", 1), ("rvalid", 1), ("rdata", data_bits), ("rlast", 1)] {
            b.output(name, held.resize(w));
        }
        let m = b.finish();
        let mut mem = MemoryModel::new(image.clone(), base, data_bits, timing);
        let (mut stimuli, mut outputs) = (Vec::new(), Vec::new());
        let mut x = 99u32;
        let beat = (data_bits / 8) as u64;
        for clock in 0..3_000u32 {
            x = xorshift32(x);
            let reset = clock == 0 || x.is_multiple_of(997);
            let arlen = (x >> 4) % 16;
            let line = ((x >> 12) as u64 % (4096 / beat / 16)) * beat * 16;
            let mo = MasterOut { arvalid: x & 3 != 0, araddr: base + line, arlen, rready: (x >> 8) & 3 != 0 };
            if reset {
                mem.reset();
            } else {
                mem.clock(&mo);
            }
            let o = mem.out();
            stimuli.push(Stimulus {
                reset,
                inputs: vec![mo.arvalid as i128, mo.araddr as i128, mo.arlen as i128, mo.rready as i128],
            });
            let mask = Ty::u(data_bits).mask();
            outputs.push(vec![o.arready as u128, o.rvalid as u128, o.rdata & mask, o.rlast as u128]);
        }
        let t = Transcript { stimuli, outputs };
        for sim in Simulator::ALL.into_iter().chain([Simulator::IverilogSv]) {
            if !sim.available() {
                let _ = writeln!(std::io::stderr().lock(), "skipped: {} is not installed", sim.name());
                continue;
            }
            let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
                .join(format!("memory_model_{}_{data_bits}", sim.name()));
            // The model's file replaces the stand-in's printed one.
            let model = model_files(&timing, data_bits, addr_bits, base, &image, sim == Simulator::Ghdl);
            let (passed, failed) = replay(&m, &t, sim, &dir, &model).unwrap_or_else(|e| panic!("{e}"));
            eprintln!("{} at {data_bits} bits: {passed} passed, {failed} failed", sim.name());
            assert_eq!((passed, failed), (3_000, 0), "{} at {data_bits} bits, {timing:?}", sim.name());
        }
    }
}

/// An external-memory core (the Cornell box, tiny caches, the memory slow and pausing, the ray
/// source stalling) in every
/// HDL simulator with the testbench's memory model: every result right (the testbench checks
/// each against the golden model) and the result stream the Rust simulator's, in order and on
/// the same clock count.
#[test]
fn external_memory_cores_run_alike_in_every_simulator() {
    use fxrt::cores::memory_params::MemorySpec;
    use fxrt::cores::top::{CoreParams, CoreSpec};
    use fxrt::model::camera::Camera;
    use fxrt::params::Params;
    use fxrt::scene::images::SceneRoms;
    use fxrt::scene::memory::SceneImage;
    use fxrt::scene::{Scene, SceneSource};
    use fxrt::verify::feed::Stalls;
    use fxrt::verify::frame::{frame_rays, frame_stream, mismatches, run_stream};
    use fxrt::verify::frame_memory::simulate_external;
    let scene =
        Scene::load(&SceneSource::Builtin("cornell".into()), &Params { n: 16, m: 16, ..Params::default() }).unwrap();
    let roms = SceneRoms::of(&scene);
    let rays = frame_rays(&scene, &Camera::default_for(&scene, 6, 5));
    let spec = MemorySpec { node_cache_kb: 1, tri_cache_kb: 1, ..MemorySpec::default() };
    let p = CoreParams::external(&roms, &CoreSpec { id_width: 8, slots: 8, ..CoreSpec::default() }, spec).unwrap();
    let timing = MemoryTiming { latency: 60, extra_delay: 20, pause_in_256: 70, seed: 5, ..MemoryTiming::default() };
    let image = SceneImage::build(&roms, spec.shape).unwrap();
    // The source stalls too (a third of the clocks): the HDL testbench's source and the Rust
    // one must hold back on the same clocks.
    let stalls = Stalls::random(33, 8);
    let (want, stats, _) = simulate_external(&p, &roms, &image, &rays, timing, &stalls, &|_| ()).unwrap();
    assert_eq!(mismatches(&scene, &rays, &want), 0);
    let mut stream = frame_stream(&p, &scene, &rays, &stalls).unwrap();
    stream.memory = Some((timing, image.bytes.clone()));
    for sim in Simulator::ALL.into_iter().chain([Simulator::IverilogSv]) {
        if !sim.available() {
            let _ = writeln!(std::io::stderr().lock(), "skipped: {} is not installed", sim.name());
            continue;
        }
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("memory_core_{}", sim.name()));
        let (got, hdl) = run_stream(sim, &stream, &dir).unwrap_or_else(|e| panic!("{}: {e}", sim.name()));
        eprintln!("{}: {} cycles (Rust {})", sim.name(), hdl.cycles, stats.cycles);
        assert_eq!(got, want, "{}: the result stream", sim.name());
        assert_eq!((hdl.cycles, hdl.busy_cycles), (stats.cycles, stats.busy_cycles), "{}", sim.name());
    }
}
