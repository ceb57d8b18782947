//! The command line's parsers and each command's validation (`config`).

use super::args::{parse_percent, parse_size, parse_vec3};
use super::config::*;
use super::sweep_config::SweepConfig;
use super::*;
use crate::error::Result;
use crate::params::EdgeShift;
use crate::verify::simulators::Simulator;
use clap::Parser;
use std::path::PathBuf;

#[test]
fn parsers() {
    assert_eq!(parse_vec3("1,-2.5,3").unwrap(), [1.0, -2.5, 3.0]);
    assert!(parse_vec3("1,2").is_err());
    assert!(parse_vec3("1,nan,2").is_err());
    assert_eq!(parse_size("640x480").unwrap(), (640, 480));
    assert!(parse_size("0x4").is_err());
}

#[test]
fn a_parse_error_is_one_line_naming_the_option() {
    let e = Cli::try_parse_from(["fxrt", "render", "--size", "0x4"]).unwrap_err();
    let line = error_line(&e);
    assert!(line.contains("--size") && line.contains("out of range"), "{line}");
    assert!(!line.contains('\n') && !line.starts_with("error"), "{line}");
}

#[test]
fn render_args_parse_without_side_effects() {
    let cli = Cli::try_parse_from([
        "fxrt",
        "render",
        "--builtin",
        "cornell",
        "--eye",
        "-1,2,3",
        "--n",
        "20",
        "--edge-shift",
        "10",
    ])
    .unwrap();
    let Some(Command::Render(r)) = cli.command else { panic!("not render") };
    assert_eq!(r.scene.source(), crate::scene::SceneSource::Builtin("cornell".into()));
    assert_eq!(r.camera.eye, Some([-1.0, 2.0, 3.0]));
    let p = r.params.params().unwrap();
    assert_eq!((p.n, p.edge_shift), (20, EdgeShift::Fixed(10)));
}

fn command(args: &[&str]) -> Command {
    Cli::try_parse_from(std::iter::once("fxrt").chain(args.iter().copied())).expect("parses").command_or_default()
}

/// `config` of any command, for what it refuses.
fn check(args: &[&str]) -> Result<()> {
    match command(args) {
        Command::Render(a) => a.config().map(drop),
        Command::Scene(a) => a.config().map(drop),
        Command::Compare(a) => a.config().map(drop),
        Command::Bench(a) => a.config().map(drop),
        Command::Gen(a) => a.config().map(drop),
        Command::Test(a) => a.config().map(drop),
        Command::Synth(a) => a.config().map(drop),
        Command::Sim(a) => a.config().map(drop),
        Command::Sweep(a) => a.config().map(drop),
        Command::Demo(a) => a.config().map(drop),
    }
}

fn refused(args: &[&str]) -> String {
    check(args).expect_err("should be refused").subject
}

#[test]
fn threads_are_1_to_1024_or_all_cores() {
    assert_eq!(threads(None), Ok(None));
    assert_eq!(threads(Some(1024)), Ok(Some(1024)));
    assert_eq!(threads(Some(0)).unwrap_err().subject, "--threads");
    assert!(threads(Some(1025)).is_err());
    for args in [&["render", "--threads", "0"][..], &["compare", "--threads", "2000"], &["bench", "--threads", "0"]] {
        assert_eq!(refused(args), "--threads", "{args:?}");
    }
    assert_eq!(refused(&["sweep", "--out", "x", "--threads", "0"]), "--threads");
    // `bench sim` runs no thread pool.
    assert!(check(&["bench", "sim", "--threads", "0"]).is_ok());
}

#[test]
fn the_default_job_is_the_demo() {
    let Command::Demo(a) = command(&[]) else { panic!("not the demo") };
    let c = a.config().unwrap();
    assert_eq!(c.out, PathBuf::from("fxrt-out"));
    assert_eq!((c.width, c.height), (128, 128));
    // Its frame stays small enough for the demo's minute.
    let Command::Demo(a) = command(&["demo", "--size", "257x8"]) else { panic!() };
    assert!(a.config().unwrap_err().to_string().starts_with("--size: 257x8"));
}

#[test]
fn bench_counts_at_least_one() {
    let Command::Bench(a) = command(&["bench", "--repeat", "0", "--size", "64x32"]) else { panic!() };
    assert_eq!(a.config(), Ok(BenchConfig::Render { width: 64, height: 32, threads: 1, repeat: 1 }));
    let Command::Bench(a) = command(&["bench", "sim", "--vectors", "0"]) else { panic!() };
    assert_eq!(a.config(), Ok(BenchConfig::Sim { vectors: 1, ghdl_vectors: 3000 }));
}

#[test]
fn bench_against_embree_takes_one_and_the_given_threads_and_only_renders() {
    let args = ["bench", "--against-embree", "--threads", "3", "--size", "8x4"];
    let Command::Bench(a) = command(&args) else { panic!() };
    assert_eq!(a.config(), Ok(BenchConfig::AgainstEmbree { width: 8, height: 4, threads: 3, repeat: 3 }));
    assert_eq!(refused(&["bench", "--against-embree", "--threads", "0"]), "--threads");
    assert_eq!(refused(&["bench", "sim", "--against-embree"]), "--against-embree");
}

#[test]
fn gen_checks_its_ranges_and_the_scene_folder() {
    assert_eq!(refused(&["gen", "--out", "x", "--scene", "rom", "--raygen"]), "--raygen");
    for w in ["0", "65"] {
        assert_eq!(refused(&["gen", "--out", "x", "--ray-id-width", w]), "--ray-id-width");
    }
    // The clock target, also under its old name (it was only the UCF's clock).
    for (flag, mhz) in [("target", "0"), ("target", "49"), ("target", "401"), ("target", "1000")] {
        let arg = format!("--{flag}-mhz={mhz}");
        assert_eq!(refused(&["gen", "--out", "x", &arg]), "--target-mhz", "{arg}");
    }
    assert_eq!(refused(&["gen", "--out", "x", "--n", "99"]), "--n");
    // A scene folder brings its own parameters: the command line's are not used.
    let Command::Gen(a) = command(&["gen", "--out", "x", "--scene", "rom", "--n", "99", "--lang", "vhdl"]) else {
        panic!()
    };
    let c = a.config().unwrap();
    assert_eq!(c.scene, GenScene::Folder("rom".into()));
    assert!(c.vhdl && !c.verilog);
    let Command::Gen(a) = command(&["gen", "--out", "x", "--raygen", "--eye", "1,2,3", "--target-mhz", "200"]) else {
        panic!()
    };
    let GenScene::Scene { raygen: Some(cam), .. } = a.config().unwrap().scene else { panic!("no camera") };
    assert_eq!(cam.eye, Some([1.0, 2.0, 3.0]));
    // --clock-mhz is sim's reporting clock; gen's clock target is only --target-mhz.
    assert!(Cli::try_parse_from(["fxrt", "gen", "--out", "x", "--clock-mhz", "200"]).is_err());
}

#[test]
fn test_fills_in_vectors_and_build_folders_per_simulator() {
    let config = |args: &[&str]| {
        let Command::Test(a) = command(args) else { panic!() };
        a.config().unwrap()
    };
    let c = config(&["test"]);
    assert_eq!((c.sim, c.vectors, c.build), (Simulation::Rust, 100_000, None));
    let c = config(&["test", "--sim", "ghdl"]);
    assert_eq!((c.vectors, c.build), (2_000, Some(PathBuf::from("target/fxrt-test/ghdl"))));
    assert_eq!(config(&["test", "--sim", "iverilog"]).vectors, 20_000);
    let c = config(&["test", "--sim", "verilator", "--build", "b", "--vectors", "7"]);
    assert_eq!((c.sim, c.vectors, c.build), (Simulation::Hdl(Simulator::Verilator), 7, Some("b".into())));
    assert_eq!(refused(&["test", "--vectors", "0"]), "--vectors");
    assert_eq!(refused(&["test", "--t", "40"]), "--t");
}

#[test]
fn sim_runs_the_ray_generator_in_rust_only() {
    assert_eq!(refused(&["sim", "--raygen", "--sim", "ghdl"]), "--raygen");
    assert_eq!(refused(&["sim", "--raygen", "--sim", "verilator"]), "--raygen");
    assert!(check(&["sim", "--raygen"]).is_ok());
    let Command::Sim(a) = command(&["sim", "--sim", "verilator"]) else { panic!() };
    let c = a.config().unwrap();
    assert_eq!((c.sim.name(), c.build), ("verilator", Some(PathBuf::from("target/fxrt-sim/verilator"))));
}

#[test]
fn sim_feed_options_are_checked() {
    let config = |args: &[&str]| {
        let Command::Sim(a) = command(args) else { panic!() };
        a.config().unwrap()
    };
    let c = config(&["sim"]);
    assert_eq!((c.shuffle_seed, c.stalls), (None, None));
    let c = config(&["sim", "--shuffle-seed", "7", "--stall-percent", "25"]);
    assert_eq!((c.shuffle_seed, c.stalls), (Some(7), Some((25, 1))));
    let c = config(&["sim", "--stall-percent", "99", "--stall-seed", "3", "--sim", "ghdl"]);
    assert_eq!(c.stalls, Some((99, 3)));
    assert_eq!(config(&["sim", "--stall-percent", "0"]).stalls, None);
    assert_eq!(parse_percent("99"), Ok(99));
    assert!(parse_percent("100").is_err() && parse_percent("-5").is_err() && parse_percent("x").is_err());
    assert_eq!(refused(&["sim", "--stall-seed", "3"]), "--stall-seed");
    assert_eq!(refused(&["sim", "--raygen", "--shuffle-seed", "1"]), "--shuffle-seed");
    assert_eq!(refused(&["sim", "--raygen", "--stall-percent", "10"]), "--stall-percent");
    for bad in
        [&["sim", "--shuffle-seed", "-1"][..], &["sim", "--stall-percent", "x"], &["sim", "--stall-percent", "100"]]
    {
        let e = Cli::try_parse_from(std::iter::once("fxrt").chain(bad.iter().copied())).unwrap_err();
        assert!(error_line(&e).contains(bad[1]), "{}", error_line(&e));
    }
}

#[test]
fn synth_defaults_to_virtex_5_and_refuses_other_families() {
    assert_eq!(refused(&["synth", "--family", "xc4"]), "--family");
    let Command::Synth(a) = command(&["synth"]) else { panic!() };
    let c = a.config().unwrap();
    assert_eq!((c.build, c.family, c.bram_kbits), (PathBuf::from("target/fxrt-synth"), Family::Xc5v, 5_328));
    // Each family's block RAM is its own part's.
    let Command::Synth(a) = command(&["synth", "--family", "xc7"]) else { panic!() };
    assert_eq!((a.config().unwrap().family, a.config().unwrap().bram_kbits), (Family::Xc7, 4_860));
    // A device is mapped by its own family only; the family decides how products are cut.
    assert_eq!(refused(&["synth", "--family", "ecp5", "--device", "xc5vlx110t"]), "--device");
    assert_eq!(refused(&["synth", "--device", "lfe5u-85f"]), "--device");
    let Command::Synth(a) = command(&["synth", "--family", "xc7", "--device", "xc7a100t"]) else { panic!() };
    assert_eq!(a.config().unwrap().family.piece(), crate::cores::mul::Piece::Dsp48);
}

#[test]
fn sweep_defaults_and_the_slurm_options() {
    assert_eq!(refused(&["sweep", "--out", "x", "--emit-slurm", "--shard", "1/2"]), "--emit-slurm");
    assert_eq!(refused(&["sweep", "--out", "x", "--fov", "180"]), "--fov");
    let run = |args: &[&str]| {
        let Command::Sweep(a) = command(args) else { panic!() };
        match a.config().unwrap() {
            SweepConfig::Run(r) => r,
            SweepConfig::Merge { .. } => panic!("not a run"),
        }
    };
    let r = run(&["sweep", "--out", "x", "--m", "16,32"]);
    assert_eq!((r.cache, r.slurm, r.plan.configs.len()), (PathBuf::from("x/cache"), None, 2));
    assert_eq!(run(&["sweep", "--out", "x", "--emit-slurm"]).slurm, Some((8, 4)));
    let r = run(&["sweep", "--out", "x", "--emit-slurm", "--shards", "3", "--threads", "2", "--cache", "c"]);
    assert_eq!((r.slurm, r.cache), (Some((3, 2)), PathBuf::from("c")));
    let Command::Sweep(a) = command(&["sweep", "merge", "a", "b", "--out", "x"]) else { panic!() };
    let SweepConfig::Merge { dirs, out, cache } = a.config().unwrap() else { panic!("not a merge") };
    assert_eq!((dirs.len(), out, cache), (2, PathBuf::from("x"), None));
}

/// The command line `--emit-slurm` writes for each shard describes the same sweep.
#[test]
fn the_emitted_sweep_command_describes_the_same_sweep() {
    let spec = |args: &[&str]| {
        let Command::Sweep(a) = command(args) else { panic!("not a sweep") };
        a.spec().unwrap()
    };
    let s = spec(&[
        "sweep",
        "/data/my scene.obj",
        "--builtin",
        "teapot,cornell",
        "--eye",
        "1.5,-2,0.001",
        "--m",
        "12,32",
        "--edge-shift",
        "auto,8",
        "--one-at-a-time",
        "--core-sim",
        "--out",
        "x",
    ]);
    let mut argv = crate::sweep::slurm::sweep_command(std::path::Path::new("/opt/fxrt"), &s);
    assert_eq!(argv[..2], ["/opt/fxrt", "sweep"]);
    argv.extend(["--out".into(), "y".into()]);
    let argv: Vec<&str> = argv.iter().skip(1).map(|a| a.as_str()).collect();
    assert_eq!(spec(&argv), s);
}

/// `--leaf-size`, `--slots` and `--units` take lists like the other axes, are checked against
/// their ranges before anything runs (naming the option), and the emitted command line
/// reproduces them.
#[test]
fn sweep_leaf_size_slots_and_units_take_lists() {
    let spec = |args: &[&str]| {
        let Command::Sweep(a) = command(args) else { panic!("not a sweep") };
        a.spec()
    };
    let s = spec(&["sweep", "--out", "x", "--slots", "2,8..16:8", "--units", "1..2", "--leaf-size", "4,2,4"]).unwrap();
    assert_eq!((&s.slots[..], &s.units[..], &s.leaf_size[..]), (&[2, 8, 16][..], &[1, 2][..], &[4, 2][..]));
    assert_eq!(s.plan().unwrap().configs.len(), 3 * 2 * 2);
    let d = spec(&["sweep", "--out", "x"]).unwrap();
    assert_eq!((&d.slots[..], &d.units[..], &d.leaf_size[..]), (&[64][..], &[2][..], &[4][..]));
    for (args, message) in [
        (&["--slots", "2,65"][..], "--slots: 65 (in '65') is out of range: must be 1..=64"),
        (&["--slots", "0..8:4"], "--slots: 0 (in '0..8:4') is out of range: must be 1..=64"),
        (&["--units", "9"], "--units: 9 (in '9') is out of range: must be 1..=8"),
        (&["--units", "2,,4"], "--units: '2,,4' has an empty item"),
        (&["--leaf-size", "0,4"], "--leaf-size: 0 (in '0') is out of range: must be 1..=64"),
        (&["--leaf-size", "8..4"], "--leaf-size: '8..4' is reversed: write 4..8"),
    ] {
        let e = check(&[&["sweep", "--out", "x"][..], args].concat()).expect_err("refused");
        assert!(e.to_string().starts_with(message), "{args:?}: {e}");
        assert_eq!(e.subject, args[0], "{args:?}");
    }
    // What --emit-slurm writes for each shard describes the same sweep.
    let mut argv = crate::sweep::slurm::sweep_command(std::path::Path::new("/opt/fxrt"), &s);
    let line = argv.join(" ");
    assert!(line.contains("--leaf-size 4,2") && line.contains("--slots 2,8,16 --units 1,2"), "{line}");
    argv.extend(["--out".into(), "x".into()]);
    let argv: Vec<&str> = argv.iter().skip(1).map(|a| a.as_str()).collect();
    assert_eq!(spec(&argv).unwrap(), s);
}

#[test]
fn each_simulator_choice_maps_once() {
    assert_eq!(Simulation::from(SimChoice::Rust), Simulation::Rust);
    assert_eq!(Simulation::from(FrameSim::Rust), Simulation::Rust);
    for (choice, frame, sim) in [
        (SimChoice::Ghdl, Some(FrameSim::Ghdl), Simulator::Ghdl),
        (SimChoice::Iverilog, None, Simulator::Iverilog),
        (SimChoice::IverilogSv, None, Simulator::IverilogSv),
        (SimChoice::Verilator, Some(FrameSim::Verilator), Simulator::Verilator),
    ] {
        assert_eq!(Simulation::from(choice), Simulation::Hdl(sim));
        assert_eq!(frame.map(Simulation::from), frame.map(|_| Simulation::Hdl(sim)));
        // The names printed before the mapping moved here: `{:?}` and its lower case.
        assert_eq!(Simulation::from(choice).title(), format!("{choice:?}"));
        // The JSON names the simulator as the option does (`--sim iverilog-sv`).
        let value = clap::ValueEnum::to_possible_value(&choice).expect("a value");
        assert_eq!(Simulation::from(choice).name(), value.get_name());
    }
}

#[test]
fn synth_ecp5_options_are_checked() {
    let Command::Synth(a) = command(&["synth", "--family", "ecp5", "--modules", "divider,core", "--target-mhz", "150"])
    else {
        panic!()
    };
    let c = a.config().unwrap();
    assert_eq!(
        c.family,
        Family::Ecp5 {
            target_mhz: 150.0,
            seeds: vec![1],
            placer: crate::fpga::ecp5::Placer::Heap,
            modules: vec!["divider".into(), "core".into()]
        }
    );
    let Command::Synth(a) = command(&["synth", "--family", "ecp5", "--placer", "static"]) else { panic!() };
    assert!(matches!(a.config().unwrap().family, Family::Ecp5 { placer: crate::fpga::ecp5::Placer::Static, .. }));
    assert_eq!(refused(&["synth", "--family", "ecp5", "--placer", "sa"]), "--placer");
    let Command::Synth(a) = command(&["synth", "--family", "ecp5", "--seeds", "2..4"]) else { panic!() };
    assert!(matches!(a.config().unwrap().family, Family::Ecp5 { seeds, .. } if seeds == [2, 3, 4]));
    let Command::Synth(a) = command(&["synth", "--family", "ecp5", "--seed", "7"]) else { panic!() };
    assert!(matches!(a.config().unwrap().family, Family::Ecp5 { seeds, .. } if seeds == [7]));
    assert_eq!(refused(&["synth", "--family", "ecp5", "--seeds", "3..1"]), "--seeds");
    assert_eq!(refused(&["synth", "--family", "ecp5", "--modules", "divider,alu"]), "--modules");
    assert_eq!(refused(&["synth", "--family", "ecp5", "--target-mhz", "0"]), "--target-mhz");
    assert_eq!(refused(&["synth", "--family", "xc4"]), "--family");
}

#[test]
fn sim_takes_a_clock_or_a_measured_fmax() {
    let Command::Sim(a) = command(&["sim", "--clock-mhz", "125"]) else { panic!() };
    assert_eq!(a.config().unwrap().clock, Some((125.0, false)));
    assert_eq!(refused(&["sim", "--clock-mhz", "0"]), "--clock-mhz");
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("t.json");
    let doc = r#"{"modules":[{"module":"fxrt_div","fmax_mhz":114.1},{"module":"fxrt_core","fmax_mhz":21.2}]}"#;
    std::fs::write(&json, doc).unwrap();
    let Command::Sim(a) = command(&["sim", "--fmax-json", json.to_str().unwrap()]) else { panic!() };
    assert_eq!(a.config().unwrap().clock, Some((21.2, true)));
    std::fs::write(&json, r#"{"modules":[{"module":"a","fmax_mhz":114.1},{"module":"b","fmax_mhz":90.5}]}"#).unwrap();
    assert_eq!(fmax_of(&json).unwrap(), 90.5);
    std::fs::write(&json, "{}").unwrap();
    assert!(fmax_of(&json).is_err());
}

/// `sweep --synth --family ecp5`: its options, refused alone or out of range, and the modules
/// in the one order the columns use.
#[test]
fn sweep_ecp5_options_are_checked() {
    let spec = |args: &[&str]| {
        let Command::Sweep(a) = command(args) else { panic!("not a sweep") };
        a.spec().unwrap()
    };
    let s = spec(&["sweep", "--out", "x"]);
    assert_eq!((s.target_mhz, &s.ecp5), (crate::cores::clock::DEFAULT_TARGET_MHZ, &None));
    assert!(!s.xc5v_synth());
    assert!(spec(&["sweep", "--out", "x", "--synth", "--family", "xc5v"]).xc5v_synth());
    let s = spec(&["sweep", "--out", "x", "--synth", "--family", "ecp5"]);
    assert_eq!(s.ecp5, Some(crate::sweep::Ecp5Choice { modules: vec!["core".into()], seed: 1 }));
    assert!(!s.xc5v_synth(), "no Virtex-5 area in an ecp5 sweep");
    let args = ["sweep", "--out", "x", "--synth", "--family", "ecp5", "--modules", "core,divider,core", "--seed", "7"];
    let s = spec(&[&args[..], &["--target-mhz", "100"]].concat());
    assert_eq!(s.ecp5, Some(crate::sweep::Ecp5Choice { modules: vec!["divider".into(), "core".into()], seed: 7 }));
    assert_eq!(s.target_mhz, 100);
    for (args, subject) in [
        (&["--family", "ecp5"][..], "--family"),
        (&["--synth", "--family", "xc7"], "--family"),
        (&["--synth", "--family", "ecp5", "--modules", "core,alu"], "--modules"),
        (&["--synth", "--family", "ecp5", "--modules", ""], "--modules"),
        (&["--synth", "--seed", "3"], "--seed"),
        (&["--modules", "core"], "--modules"),
        (&["--target-mhz", "49"], "--target-mhz"),
        (&["--synth", "--family", "ecp5", "--target-mhz", "401"], "--target-mhz"),
    ] {
        assert_eq!(refused(&[&["sweep", "--out", "x"][..], args].concat()), subject, "{args:?}");
    }
    // What --emit-slurm writes for each shard describes the same ecp5 sweep.
    let mut argv = crate::sweep::slurm::sweep_command(std::path::Path::new("/opt/fxrt"), &s);
    argv.extend(["--out".into(), "y".into()]);
    let argv: Vec<&str> = argv.iter().skip(1).map(|a| a.as_str()).collect();
    assert_eq!(spec(&argv), s);
    assert!(argv.join(" ").contains("--target-mhz 100 --family ecp5 --seed 7 --modules divider,core"), "{argv:?}");
}

/// `--tree` is accepted wherever the parameters are (and `sweep`, as one value), `middle` by
/// default; a bad value is one line naming the option.
#[test]
fn every_command_with_parameters_takes_tree() {
    use crate::params::TreeSplit;
    let tree = |args: &[&str]| match command(args) {
        Command::Render(a) => a.params.params().unwrap().tree,
        Command::Scene(a) => a.params.params().unwrap().tree,
        Command::Compare(a) => a.params.params().unwrap().tree,
        Command::Gen(a) => a.params.params().unwrap().tree,
        Command::Test(a) => a.params.params().unwrap().tree,
        Command::Synth(a) => a.params.params().unwrap().tree,
        Command::Sim(a) => a.params.params().unwrap().tree,
        Command::Sweep(a) => a.spec().unwrap().defaults().tree,
        Command::Bench(_) | Command::Demo(_) => panic!("bench and demo take no parameters"),
    };
    for cmd in ["render", "scene", "compare", "gen", "test", "synth", "sim", "sweep"] {
        let out: &[&str] = if matches!(cmd, "sweep" | "scene" | "gen") { &["--out", "x"] } else { &[] };
        assert_eq!(tree(&[&[cmd], out].concat()), TreeSplit::Sah, "{cmd}");
        assert_eq!(tree(&[&[cmd, "--tree", "sah"], out].concat()), TreeSplit::Sah, "{cmd}");
        assert_eq!(tree(&[&[cmd, "--tree", "middle"], out].concat()), TreeSplit::Middle, "{cmd}");
        let e = Cli::try_parse_from([&["fxrt", cmd, "--tree", "median"], out].concat()).unwrap_err();
        let line = error_line(&e);
        assert!(line.contains("--tree") && line.contains("middle or sah"), "{cmd}: {line}");
    }
    // A sweep's shards are started with the same tree; the default adds nothing to the line.
    let Command::Sweep(a) = command(&["sweep", "--tree", "middle", "--out", "x"]) else { panic!("not a sweep") };
    let argv = crate::sweep::slurm::sweep_command(std::path::Path::new("/opt/fxrt"), &a.spec().unwrap());
    assert!(argv.windows(2).any(|w| w == ["--tree", "middle"]), "{argv:?}");
    let Command::Sweep(a) = command(&["sweep", "--out", "x"]) else { panic!("not a sweep") };
    let argv = crate::sweep::slurm::sweep_command(std::path::Path::new("/opt/fxrt"), &a.spec().unwrap());
    assert!(!argv.iter().any(|w| w == "--tree"), "{argv:?}");
}
