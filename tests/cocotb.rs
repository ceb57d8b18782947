//! The cocotb testbench of the AXI4-Stream wrapper (testbenches/cocotb/test_axis.py) on the
//! generated VHDL in GHDL and the generated Verilog in Icarus and Verilator: a 16×16 Cornell
//! frame in frames of 50 rays, random tvalid and tready, every result against the golden
//! model's `expected.bin`. Then one byte of `expected.bin` is changed and the testbench must
//! fail. The same testbench drives the external-memory core with cocotbext-axi's AxiRamRead
//! behind its read port, in Icarus and Verilator. Without cocotb or cocotbext-axi
//! (scripts/install-deps.sh puts both in .venv) or a simulator, says "skipped: …" and passes.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

/// `$FXRT_PYTHON`, else the project's .venv, else python3 — if it imports cocotb.
fn python() -> Option<PathBuf> {
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    let candidates: Vec<PathBuf> = match std::env::var_os("FXRT_PYTHON") {
        Some(p) => vec![PathBuf::from(p)],
        None => vec![venv, PathBuf::from("python3")],
    };
    candidates
        .into_iter()
        .find(|p| Command::new(p).args(["-c", "import cocotb"]).output().is_ok_and(|o| o.status.success()))
}

fn imports(python: &Path, module: &str) -> bool {
    Command::new(python).args(["-c", &format!("import {module}")]).output().is_ok_and(|o| o.status.success())
}

fn installed(tool: &str) -> bool {
    let flag = if tool == "iverilog" { "-V" } else { "--version" };
    Command::new(tool).arg(flag).output().is_ok()
}

/// Runs the testbench in `sim`: (passed, the output's last lines).
fn run(python: &Path, sim: &str, dir: &Path, top: &str) -> (bool, String) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("testbenches/cocotb/run.py");
    let out = Command::new(python)
        .arg(&script)
        .args(["--sim", sim, "--top", top, "--frame", "50", "--seed", "3", "--dir"])
        .arg(dir)
        .output()
        .expect("python runs");
    let text = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    let tail: Vec<&str> = text.lines().rev().take(25).collect();
    let tail = tail.into_iter().rev().collect::<Vec<_>>().join("\n");
    let passed = out.status.success() && text.contains(&format!("cocotb {sim}: 1 passed, 0 failed"));
    (passed, tail)
}

/// The simulators of `wanted` (cocotb's name, the tool) that are installed; says which are not.
fn simulators<'a>(wanted: &[(&'a str, &'a str)]) -> Vec<(&'a str, &'a str)> {
    wanted
        .iter()
        .copied()
        .filter(|(sim, tool)| {
            let ok = installed(tool);
            if !ok {
                common::say(&format!("skipped: the cocotb testbench in {sim}: {tool} is not installed"));
            }
            ok
        })
        .collect()
}

/// `fxrt gen --axis-frame` with `args` into `dir`: the wrapper's name (it carries the core's,
/// with its scene tag; its manifest says it).
fn generate_wrapper(dir: &Path, args: &[&str]) -> String {
    let generated = Command::new(env!("CARGO_BIN_EXE_fxrt")).args(args).arg("--out").arg(dir).output().unwrap();
    assert!(generated.status.success(), "{}", String::from_utf8_lossy(&generated.stderr));
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.unwrap().file_name().into_string().ok())
        .find_map(|n| n.strip_suffix("_axis.json").map(|core| format!("{core}_axis")))
        .expect("the wrapper's manifest")
}

#[test]
fn the_cocotb_testbench_passes_in_ghdl_icarus_and_verilator() {
    let Some(python) = python() else {
        common::say("skipped: cocotb is not installed (scripts/install-deps.sh puts cocotb 1.8.1 into .venv)");
        return;
    };
    let sims = simulators(&[("ghdl", "ghdl"), ("icarus", "iverilog"), ("verilator", "verilator")]);
    if sims.is_empty() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let top = generate_wrapper(dir.path(), &["gen", "--builtin", "cornell", "--size", "16x16", "--axis-frame"]);
    for &(sim, _) in &sims {
        let start = std::time::Instant::now();
        let (passed, tail) = run(&python, sim, dir.path(), &top);
        assert!(passed, "cocotb in {sim}:\n{tail}");
        common::say(&format!("cocotb {sim}: passed in {:.0} s", start.elapsed().as_secs_f64()));
    }
    // One wrong bit in the expected results (a byte of u in the middle ray's: 196 results of
    // 32 bytes) must fail the testbench.
    let (sim, _) = sims.iter().find(|s| s.0 == "icarus").unwrap_or(&sims[0]);
    let expected = dir.path().join("expected.bin");
    let mut bytes = std::fs::read(&expected).unwrap();
    assert_eq!(bytes.len(), 196 * 32);
    bytes[98 * 32 + 10] ^= 1;
    std::fs::write(&expected, &bytes).unwrap();
    let (passed, tail) = run(&python, sim, dir.path(), &top);
    assert!(!passed, "a corrupted expected.bin passed in {sim}:\n{tail}");
}

/// The core with its scene in external memory, behind the same wrapper, reads scene.bin through
/// its AXI4 read port from a third-party model (cocotbext-axi's `AxiRamRead`, RVALID paused at
/// random) in Icarus and Verilator: the teapot at 16×16 with 2 KB node caches and a 4 KB
/// triangle cache, so lines are evicted and read again (about 2,000 bursts); every result
/// against the golden model's. Then the image's triangles are scrambled and the test must fail:
/// the results come from what the core read.
#[test]
fn the_external_memory_core_reads_its_scene_from_cocotbext_axi_in_icarus_and_verilator() {
    let Some(python) = python() else {
        common::say("skipped: cocotb is not installed (scripts/install-deps.sh puts cocotb 1.8.1 into .venv)");
        return;
    };
    if !imports(&python, "cocotbext.axi") {
        common::say("skipped: cocotbext-axi is not installed (scripts/install-deps.sh puts it into .venv)");
        return;
    }
    let sims = simulators(&[("icarus", "iverilog"), ("verilator", "verilator")]);
    if sims.is_empty() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let args = ["gen", "--builtin", "teapot", "--size", "16x16", "--axis-frame", "--memory", "external"];
    let top = generate_wrapper(dir.path(), &[&args[..], &["--node-cache-kb", "2", "--tri-cache-kb", "4"]].concat());
    for &(sim, _) in &sims {
        let start = std::time::Instant::now();
        let (passed, tail) = run(&python, sim, dir.path(), &top);
        assert!(passed, "cocotb with AxiRamRead in {sim}:\n{tail}");
        assert!(tail.contains("bursts read from AxiRamRead"), "{tail}");
        common::say(&format!("cocotb {sim}, scene in AxiRamRead: passed in {:.0} s", start.elapsed().as_secs_f64()));
    }
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join(format!("{top}.json"))).unwrap()).unwrap();
    let tri_offset = manifest["memory"]["image"]["tri_offset"].as_u64().expect("the image's triangle offset") as usize;
    let image = dir.path().join("scene.bin");
    let mut bytes = std::fs::read(&image).unwrap();
    for b in &mut bytes[tri_offset..] {
        *b ^= 0x5a;
    }
    std::fs::write(&image, &bytes).unwrap();
    let (sim, _) = sims.iter().find(|s| s.0 == "verilator").unwrap_or(&sims[0]);
    let (passed, tail) = run(&python, sim, dir.path(), &top);
    assert!(!passed, "scrambled triangles in scene.bin passed in {sim}:\n{tail}");
}
