//! The intersection pipeline's generated HDL against the golden model in every simulator, at
//! the defaults and at widths chosen to stress the RTL layer. A simulator that is not
//! installed is reported as skipped (scripts/test.sh installs them all).

mod common;

use fxrt::cores::intersect::IntersectParams;
use fxrt::cores::mul::Piece;
use fxrt::params::Params;
use fxrt::scene::{Scene, SceneSource};
use fxrt::verify::check::{run_hdl, run_rust};
use fxrt::verify::simulators::Simulator;
use fxrt::verify::vectors::generate;

fn setup(params: Params, count: usize) -> (IntersectParams, Vec<fxrt::verify::vectors::Vector>) {
    setup_bits(params, 1, count)
}

fn setup_bits(params: Params, div_bits: u32, count: usize) -> (IntersectParams, Vec<fxrt::verify::vectors::Vector>) {
    let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &params).unwrap();
    let p = IntersectParams {
        n: params.n,
        m: params.m,
        t: params.t,
        e: scene.edge_shift,
        tag_width: 20,
        div_bits,
        target_mhz: fxrt::cores::clock::DEFAULT_TARGET_MHZ,
        piece: Default::default(),
        spread: false,
    };
    p.check().unwrap();
    let v = generate(&scene, count, 7);
    let hits = v.iter().filter(|x| x.expected.is_some()).count();
    assert!(hits > count / 20 && hits < count, "{hits} hits in {count} vectors");
    (p, v)
}

fn hdl(sim: Simulator, params: Params, count: usize) {
    hdl_bits(sim, params, 1, count)
}

fn hdl_bits(sim: Simulator, params: Params, div_bits: u32, count: usize) {
    hdl_cut(sim, params, div_bits, Piece::Mult18, count)
}

fn hdl_cut(sim: Simulator, params: Params, div_bits: u32, piece: Piece, count: usize) {
    if !sim.available() {
        common::say(&format!("skipped: {} is not installed", sim.name()));
        return;
    }
    let (p, v) = setup_bits(params, div_bits, count);
    let p = IntersectParams { piece, ..p };
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("hdl_{}_{}", sim.name(), p.name()));
    let o = run_hdl(sim, &p, &v, &dir).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((o.passed, o.failed), ((count + p.latency() as usize) as u64, 0), "{} {}", sim.name(), p.name());
}

const SMALL: Params = Params { n: 16, m: 16, ..DEFAULTS };
const ODD: Params = Params { n: 23, m: 27, t: 5, ..DEFAULTS };
const WIDE: Params = Params { n: 32, m: 40, ..DEFAULTS };
const DEFAULTS: Params = Params {
    n: 29,
    m: 32,
    edge_shift: fxrt::params::EdgeShift::Auto,
    t: 0,
    c: 16,
    leaf_size: 4,
    stack_depth: 32,
    tree: fxrt::params::TreeSplit::Middle,
    sah_step_percent: 0,
};

#[test]
fn rust_simulator_matches_golden_on_a_million_vectors_at_defaults() {
    let (p, v) = setup(DEFAULTS, 1_000_000);
    let o = run_rust(&p, &v);
    assert_eq!((o.passed, o.failed), (1_000_000, 0));
}

#[test]
fn cycle_and_batch_engines_both_match_golden() {
    use fxrt::verify::check::{Engine, run_rust_with};
    let (p, v) = setup(ODD, 20_000);
    for engine in [Engine::Cycle, Engine::Batch] {
        let (o, _) = run_rust_with(engine, &p, &v);
        assert_eq!((o.passed, o.failed), (20_000, 0), "{engine:?}");
    }
}

#[test]
fn rust_simulator_matches_golden_at_stress_widths() {
    for params in [SMALL, ODD, WIDE] {
        let (p, v) = setup(params, 100_000);
        let o = run_rust(&p, &v);
        assert_eq!((o.passed, o.failed), (100_000, 0), "{}", p.name());
    }
}

#[test]
fn ghdl_defaults() {
    hdl(Simulator::Ghdl, DEFAULTS, 1500);
}

#[test]
fn ghdl_small() {
    hdl(Simulator::Ghdl, SMALL, 1500);
}

#[test]
fn verilator_defaults() {
    hdl(Simulator::Verilator, DEFAULTS, 100_000);
}

#[test]
fn verilator_odd() {
    hdl(Simulator::Verilator, ODD, 100_000);
}

#[test]
fn two_quotient_bits_per_stage_in_ghdl_and_verilator() {
    hdl_bits(Simulator::Ghdl, SMALL, 2, 800);
    hdl_bits(Simulator::Verilator, DEFAULTS, 2, 50_000);
}

#[test]
fn iverilog_wide() {
    hdl(Simulator::Iverilog, WIDE, 3000);
}

/// The products cut for the DSP48E (`--dsp 25x18`, DECISIONS 131): at m = 40 a 41 × 41-bit
/// product is 6 pieces of 25 × 18, not 9 of 18 × 18. Verilator and GHDL agree with the golden
/// model on every vector, and yosys maps each piece to one DSP48E: as many as the estimate,
/// fewer than the 18 × 18 cut's.
#[test]
fn dsp48_pieces_match_the_golden_model_and_map_one_dsp48e_each() {
    hdl_cut(Simulator::Verilator, WIDE, 1, Piece::Dsp48, 50_000);
    hdl_cut(Simulator::Ghdl, WIDE, 1, Piece::Dsp48, 400);
    let (p, _) = setup(WIDE, 100);
    let cut = |piece| fxrt::cores::intersect::intersect_core(&IntersectParams { piece, ..p });
    let (square, dsp48) = (cut(Piece::Mult18), cut(Piece::Dsp48));
    let estimate = fxrt::cores::cost::dsp48e_estimate(&dsp48);
    assert!(estimate < fxrt::cores::cost::dsp48e_estimate(&square), "{estimate}");
    if std::process::Command::new("yosys").arg("-V").output().is_err() {
        common::say("skipped: yosys is not installed");
        return;
    }
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("hdl_dsp48_synth");
    let area = fxrt::fpga::xilinx::synth_xc5v(&dsp48, &dir).unwrap();
    assert_eq!(area.dsp48e, estimate as u64, "{area:?}");
}

#[test]
fn generated_hdl_passes_ghdl_synth_verilator_lint_and_yosys_xc5v() {
    let (p, _) = setup(SMALL, 100);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("hdl_tools");
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in fxrt::generate::files(&p, true, true) {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let run = |prog: &str, args: &[&str]| -> Option<std::process::Output> {
        match std::process::Command::new(prog).args(args).current_dir(&dir).output() {
            Ok(o) => Some(o),
            Err(_) => {
                common::say(&format!("skipped: {prog} is not installed"));
                None
            }
        }
    };
    let name = p.name();
    // The pipeline instantiates the divider: each module is in its own file, sub-modules first.
    let module = fxrt::cores::intersect::intersect_core(&p);
    let files = |ext| {
        let all = fxrt::rtl::emit::design_files(&module, ext).into_iter().map(|f| f.0);
        all.filter(|f| fxrt::rtl::emit::is_source(f)).collect::<Vec<_>>()
    };
    let (vhd, v) = (files("vhd"), files("v"));
    // The divider, the split multipliers and their DSP piece come first, the pipeline last.
    assert_eq!(vhd.len(), module.hierarchy().len(), "{vhd:?}");
    assert_eq!(vhd.last(), Some(&format!("{name}.vhd")), "{vhd:?}");
    for sub in [format!("{}.vhd", p.divider().name), "fxrt_dsp18_r3.vhd".into()] {
        assert!(vhd.contains(&sub), "{sub} in {vhd:?}");
    }
    let mut args = vec!["--synth", "--std=93c", "--out=none"];
    args.extend(vhd.iter().map(|s| s.as_str()));
    args.extend(["-e", &name]);
    if let Some(o) = run("ghdl", &args) {
        assert!(o.status.success(), "ghdl --synth: {}", String::from_utf8_lossy(&o.stderr));
    }
    let mut args = vec!["--lint-only", "-Wall", "--top-module", &name];
    args.extend(v.iter().map(|s| s.as_str()));
    if let Some(o) = run("verilator", &args) {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success() && !err.contains("%Warning"), "verilator lint: {err}");
    }
    if run("yosys", &["-V"]).is_some() {
        let area = fxrt::fpga::xilinx::synth_xc5v(&module, &dir.join("synth")).unwrap();
        // Four products ahead of the divider, two after it, four for u and v: all on DSP48E.
        assert!(area.dsp48e >= 10, "{area:?}");
        // The sweeps' DSP48E estimate is what yosys does.
        assert_eq!(area.dsp48e, fxrt::cores::cost::dsp48e_estimate(&module) as u64);
        assert!(area.luts > 500 && area.ffs > 500, "{area:?}");
    }
}

/// The whole core (traversal, ROMs, pipeline, closest hit) of a small scene, also with its
/// ray generator: `ghdl --synth` accepts them, Verilator's lint is silent, and yosys maps the
/// core to Virtex-5 (multipliers on DSP48E, ROMs in RAM cells).
#[test]
fn whole_core_passes_ghdl_synth_verilator_lint_and_yosys_xc5v() {
    use fxrt::cores::top::{CoreParams, core_module, core_with_raygen};
    use fxrt::scene::images::SceneRoms;
    let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &SMALL).unwrap();
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::new(&roms, 12, 1, fxrt::cores::clock::DEFAULT_TARGET_MHZ);
    let mut cam = fxrt::model::camera::Camera::default_for(&scene, 32, 24);
    cam.eye = [278.0, 273.0, 60.0];
    let generator = fxrt::model::raygen::RayGen::new(&scene, &cam).unwrap();
    lint_and_ghdl_synth(
        &core_with_raygen(&p, &std::rc::Rc::new(fxrt::cores::top::core_module(&p, &roms)), &generator),
        "whole_core_raygen_tools",
    );
    let module = core_module(&p, &roms);
    let dir = lint_and_ghdl_synth(&module, "whole_core_tools");
    if std::process::Command::new("yosys").arg("-V").output().is_ok() {
        let area = fxrt::fpga::xilinx::synth_xc5v(&module, &dir.join("synth")).unwrap();
        // A small scene's ROMs fit distributed RAM; the teapot's map to block RAM (docs/CORE.md).
        assert!(area.dsp48e >= 10 && area.bram18 + area.lutram_cells > 0, "{area:?}");
        assert_eq!(area.dsp48e, fxrt::cores::cost::dsp48e_estimate(&module) as u64);
    } else {
        common::say("skipped: yosys is not installed");
    }
}

/// The Xilinx fit's block RAM count (`fpga::xilinx_bram`) is what yosys maps: each block
/// memory of the teapot's core (the ROMs of leaves, nodes with two read ports and triangles,
/// a traversal stack) synthesised alone for Virtex-5 takes the RAMB36 and RAMB18 counted.
#[test]
fn xilinx_block_ram_counts_are_what_yosys_maps() {
    use fxrt::cores::brom::{BRAM_PREFIX, BROM_PREFIX};
    use fxrt::cores::top::{CoreParams, core_module};
    use fxrt::fpga::xilinx_bram::{Brams, brams};
    if std::process::Command::new("yosys").arg("-V").output().is_err() {
        common::say("skipped: yosys is not installed");
        return;
    }
    let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &DEFAULTS).unwrap();
    let roms = fxrt::scene::images::SceneRoms::of(&scene);
    let core = core_module(&CoreParams::new(&roms, 12, 1, fxrt::cores::clock::DEFAULT_TARGET_MHZ), &roms);
    let mut memories: Vec<std::rc::Rc<fxrt::rtl::Module>> = Vec::new();
    for inst in &core.instances {
        let name = &inst.module.name;
        let block = name.starts_with(BROM_PREFIX) || name.starts_with(BRAM_PREFIX);
        if block && !memories.iter().any(|m| &m.name == name) {
            memories.push(inst.module.clone());
        }
    }
    assert!(memories.len() >= 5, "{:?}", memories.iter().map(|m| &m.name).collect::<Vec<_>>());
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("xilinx_brams");
    let mut seen = Brams::default();
    for m in &memories {
        let area = fxrt::fpga::xilinx::synth_xc5v(m, &dir.join(&m.name)).unwrap();
        let cells = |k: &str| area.cells.get(k).copied().unwrap_or(0) as u32;
        let mapped = Brams { ramb36: cells("RAMB36"), ramb18: cells("RAMB18") };
        assert_eq!(brams(m), mapped, "{}", m.name);
        seen += mapped;
    }
    // Both kinds occur, so the choice between them is checked.
    assert!(seen.ramb36 > 0 && seen.ramb18 > 0, "{seen:?}");
}

/// Writes `module`'s design in both languages under target/, then checks `ghdl --synth` and
/// `verilator --lint-only -Wall` on it (each skipped when not installed). Returns the folder.
fn lint_and_ghdl_synth(module: &fxrt::rtl::Module, folder: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(folder);
    std::fs::create_dir_all(&dir).unwrap();
    let mut sources = std::collections::HashMap::new();
    for ext in ["vhd", "v"] {
        let files = fxrt::rtl::emit::design_files(module, ext);
        for (name, text) in &files {
            std::fs::write(dir.join(name), text).unwrap();
        }
        let names: Vec<String> = files.into_iter().map(|f| f.0).filter(|f| fxrt::rtl::emit::is_source(f)).collect();
        assert_eq!(names.last(), Some(&format!("{}.{ext}", module.name)));
        sources.insert(ext, names);
    }
    let run = |prog: &str, args: &[&str]| -> Option<std::process::Output> {
        match std::process::Command::new(prog).args(args).current_dir(&dir).output() {
            Ok(o) => Some(o),
            Err(_) => {
                common::say(&format!("skipped: {prog} is not installed"));
                None
            }
        }
    };
    let mut args = vec!["--synth", "--std=93c", "--out=none"];
    args.extend(sources["vhd"].iter().map(String::as_str));
    args.extend(["-e", &module.name]);
    if let Some(o) = run("ghdl", &args) {
        assert!(o.status.success(), "ghdl --synth: {}", String::from_utf8_lossy(&o.stderr));
    }
    let mut args = vec!["--lint-only", "-Wall", "--top-module", &module.name];
    args.extend(sources["v"].iter().map(String::as_str));
    if let Some(o) = run("verilator", &args) {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success() && !err.contains("%Warning"), "verilator lint: {err}");
    }
    dir
}
