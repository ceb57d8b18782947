//! Each command's arguments validated into what it runs on: ranges checked, defaults filled
//! in, the command line's choices mapped to the library's types. Nothing here writes a file;
//! output paths are only looked at, so one that can never be written (a folder, a path below a
//! regular file, two options naming one file) is refused before anything runs. What needs the
//! scene (the camera's defaults, widths against the scene's E, the
//! core's memories) is checked in `cli::run` as soon as the scene is loaded, still before
//! anything is written.

use super::{
    BenchArgs, BenchWhat, CameraArgs, CompareArgs, FrameSim, GenArgs, HwArgs, Lang, ParamArgs, RenderArgs, SceneArgs,
    SceneChoice, SimArgs, SimChoice, SynthArgs, TestArgs,
};
use crate::error::{Error, Result};
use crate::fpga::device::Device;
use crate::io::check_folder;
use crate::model::camera::{Camera, CameraSpec};
use crate::params::Params;
use crate::render::tracer::ModelKind;
use crate::scene::SceneSource;
use crate::sweep::fit::SceneSearch;
use crate::verify::simulators::Simulator;
use std::path::PathBuf;

/// Where a design runs: the Rust simulator or an HDL simulator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simulation {
    Rust,
    Hdl(Simulator),
}

impl Simulation {
    /// As the JSON of `fxrt sim` names it: rust, ghdl, iverilog, iverilog-sv, verilator.
    pub fn name(self) -> &'static str {
        match self {
            Simulation::Rust => "rust",
            Simulation::Hdl(s) => s.name(),
        }
    }

    /// As the summary line of `fxrt test` names it.
    pub fn title(self) -> &'static str {
        match self {
            Simulation::Rust => "Rust",
            Simulation::Hdl(Simulator::Ghdl) => "Ghdl",
            Simulation::Hdl(Simulator::Iverilog) => "Iverilog",
            Simulation::Hdl(Simulator::IverilogSv) => "IverilogSv",
            Simulation::Hdl(Simulator::Verilator) => "Verilator",
        }
    }

    /// The build folder of an HDL run: `dir` if given, else `default_root`/SIMULATOR.
    fn build_dir(self, dir: &Option<PathBuf>, default_root: &str) -> Result<Option<PathBuf>> {
        match self {
            Simulation::Rust => Ok(None),
            Simulation::Hdl(s) => {
                let dir = dir.clone().unwrap_or_else(|| PathBuf::from(default_root).join(s.name()));
                check_folder(&dir)?;
                Ok(Some(dir))
            }
        }
    }
}

impl From<SimChoice> for Simulation {
    fn from(s: SimChoice) -> Self {
        match s {
            SimChoice::Rust => Simulation::Rust,
            SimChoice::Ghdl => Simulation::Hdl(Simulator::Ghdl),
            SimChoice::Iverilog => Simulation::Hdl(Simulator::Iverilog),
            SimChoice::IverilogSv => Simulation::Hdl(Simulator::IverilogSv),
            SimChoice::Verilator => Simulation::Hdl(Simulator::Verilator),
        }
    }
}

impl From<FrameSim> for Simulation {
    fn from(s: FrameSim) -> Self {
        match s {
            FrameSim::Rust => Simulation::Rust,
            FrameSim::Ghdl => Simulation::Hdl(Simulator::Ghdl),
            FrameSim::Verilator => Simulation::Hdl(Simulator::Verilator),
        }
    }
}

/// Worker threads: None for all cores, else 1..=1024.
pub fn threads(n: Option<usize>) -> Result<Option<usize>> {
    match n {
        Some(n) if n == 0 || n > 1024 => Err(Error::param("threads", format!("{n} is out of range: must be 1..=1024"))),
        n => Ok(n),
    }
}

/// The worker pool for `threads` (None: all cores).
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        b = b.num_threads(n);
    }
    b.build().map_err(|e| Error::param("threads", e.to_string()))
}

/// A frame of `width` × `height` rays numbered by pixel fits ray ids of `id_width` bits.
pub fn ids_fit(id_width: u32, width: u32, height: u32) -> Result<()> {
    let pixels = width as u64 * height as u64;
    if id_width < 64 && pixels > 1u64 << id_width {
        return Err(Error::param(
            "ray-id-width",
            format!("{id_width} bits cannot number the {pixels} pixels of --size"),
        ));
    }
    Ok(())
}

/// Output files of one command, (option, path) for those given: each can be written
/// (`io::check_writable`) and no two name one file.
pub fn check_outputs(files: &[(&str, &Option<PathBuf>)]) -> Result<()> {
    let given: Vec<(&str, &PathBuf)> = files.iter().filter_map(|(o, p)| Some((*o, p.as_ref()?))).collect();
    for (i, &(option, path)) in given.iter().enumerate() {
        crate::io::check_writable(path)?;
        let same = |p: &PathBuf| std::path::absolute(p).ok() == std::path::absolute(path).ok();
        if let Some((other, _)) = given[..i].iter().find(|(_, p)| same(p)) {
            return Err(Error::param(option, format!("{} is also the --{other} file", path.display())));
        }
    }
    Ok(())
}

/// Output files of a frame; none is written before everything is computed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FrameFiles {
    pub png: Option<PathBuf>,
    pub ids: Option<PathBuf>,
    pub depth: Option<PathBuf>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderConfig {
    pub params: Params,
    pub threads: Option<usize>,
    pub scene: SceneSource,
    pub camera: CameraSpec,
    pub model: ModelKind,
    pub shade: bool,
    pub files: FrameFiles,
}

impl RenderArgs {
    pub fn config(&self) -> Result<RenderConfig> {
        check_outputs(&[("png", &self.png), ("ids", &self.ids), ("depth", &self.depth)])?;
        Ok(RenderConfig {
            params: self.params.params()?,
            threads: threads(self.threads)?,
            scene: self.scene.source(),
            camera: self.camera.spec(),
            model: self.model,
            shade: self.shade,
            files: FrameFiles { png: self.png.clone(), ids: self.ids.clone(), depth: self.depth.clone() },
        })
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct CompareConfig {
    pub params: Params,
    pub threads: Option<usize>,
    pub scene: SceneSource,
    pub camera: CameraSpec,
    pub against: ModelKind,
}

impl CompareArgs {
    pub fn config(&self) -> Result<CompareConfig> {
        Ok(CompareConfig {
            params: self.params.params()?,
            threads: threads(self.threads)?,
            scene: self.scene.source(),
            camera: self.camera.spec(),
            against: self.against,
        })
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct SceneConfig {
    pub params: Params,
    pub scene: SceneSource,
    pub out: PathBuf,
    pub stats: bool,
    pub memory: crate::scene::memory::MemoryShape,
}

impl SceneArgs {
    pub fn config(&self) -> Result<SceneConfig> {
        check_folder(&self.out)?;
        Ok(SceneConfig {
            params: self.params.params()?,
            scene: self.scene.source(),
            out: self.out.clone(),
            stats: self.stats,
            memory: self.memory.shape()?,
        })
    }
}

/// `fxrt bench`: always the embedded teapot at the default parameters.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BenchConfig {
    /// Golden-model render speed; the best of `repeat` (≥ 1) renders.
    Render { width: u32, height: u32, threads: usize, repeat: u32 },
    /// The golden model against Embree on the same rays, with 1 and `threads` threads (the
    /// same count once when `threads` is 1), best of `repeat` (≥ 1) each.
    AgainstEmbree { width: u32, height: u32, threads: usize, repeat: u32 },
    /// Simulator speed on `vectors` (≥ 1) intersection vectors, GHDL on a prefix.
    Sim { vectors: usize, ghdl_vectors: usize },
    /// The agreement property on `netlists` (≥ 1) random netlists.
    Agree { netlists: u64 },
    /// The differential campaign of the core against the golden model.
    Exact(crate::verify::exact::Campaign),
}

impl BenchArgs {
    pub fn config(&self) -> Result<BenchConfig> {
        if self.against_embree && self.what != BenchWhat::Render {
            return Err(Error::param(
                "against-embree",
                "measures the golden model's render speed only, not `bench sim` or `bench agree`",
            ));
        }
        Ok(match self.what {
            BenchWhat::Sim => BenchConfig::Sim { vectors: self.vectors.max(1), ghdl_vectors: self.ghdl_vectors },
            BenchWhat::Agree => BenchConfig::Agree { netlists: self.netlists.max(1) },
            BenchWhat::Exact => BenchConfig::Exact(super::exact::campaign_config(self)?),
            BenchWhat::Render => {
                let ((width, height), repeat, t) = (self.size, self.repeat.max(1), threads(self.threads)?);
                if self.against_embree {
                    // One thread, then all cores (or --threads).
                    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
                    BenchConfig::AgainstEmbree { width, height, threads: t.unwrap_or(all), repeat }
                } else {
                    BenchConfig::Render { width, height, threads: t.unwrap_or(1), repeat }
                }
            }
        })
    }
}

/// Where `fxrt gen` takes its scene from.
#[derive(Clone, Debug, PartialEq)]
pub enum GenScene {
    /// A folder written by `fxrt scene` (its parameters are the ones stored there).
    Folder(PathBuf),
    /// A scene quantised with `params`; with a camera when the core has the ray generator.
    /// `search`: what `--device`'s fit may choose of the scene's build.
    Scene { source: SceneSource, params: Params, search: SceneSearch, raygen: Option<CameraSpec> },
}

#[derive(Clone, Debug, PartialEq)]
pub struct GenConfig {
    pub scene: GenScene,
    pub out: PathBuf,
    pub vhdl: bool,
    pub verilog: bool,
    pub ise: bool,
    pub debug_ports: bool,
    pub measured: Option<PathBuf>,
    pub target_mhz: u32,
    pub ray_id_width: u32,
    pub bram_kbits: u64,
    pub div_bits: u32,
    pub threads: super::ThreadArgs,
    /// The camera of the frame written for the AXI4-Stream wrapper (`--axis-frame`).
    pub axis_frame: Option<CameraSpec>,
    /// `--board`: the board design instead of the core's files (its camera in `scene`).
    pub board: Option<BoardConfig>,
    /// Where the scene lives (`auto` decided by `bram_kbits`) and the external core's options.
    pub memory: super::args::MemoryPlace,
    pub mem_spec: crate::cores::memory_params::MemorySpec,
}

impl GenConfig {
    /// The core these options describe.
    pub fn core_spec(&self) -> crate::cores::top::CoreSpec {
        crate::cores::top::CoreSpec {
            id_width: self.ray_id_width,
            div_bits: self.div_bits,
            target_mhz: self.target_mhz,
            slots: self.threads.slots,
            units: self.threads.units,
            pipelines: self.threads.pipelines,
            piece: self.threads.piece_or(Default::default()),
        }
    }
}

/// What `fxrt gen --board` builds.
#[derive(Clone, Debug, PartialEq)]
pub struct BoardConfig {
    pub board: crate::board::Board,
    pub mhz: f64,
    pub led_shift: Option<u32>,
    pub bitstream: bool,
    pub seed: u64,
}

impl GenArgs {
    pub fn config(&self) -> Result<GenConfig> {
        if self.board.is_some() {
            let clash = [
                ("raygen", self.raygen),
                ("axis-frame", self.axis_frame),
                ("ise", self.ise),
                ("debug-ports", self.debug_ports),
                ("measured", self.measured.is_some()),
                ("scene", self.scene_dir.is_some()),
            ];
            if let Some((name, _)) = clash.iter().find(|c| c.1) {
                return Err(Error::param(
                    name,
                    "not with --board (a board design has its own ray generator, pins and project)",
                ));
            }
            if !(self.board_mhz.is_finite() && (10.0..=400.0).contains(&self.board_mhz)) {
                return Err(Error::param("board-mhz", format!("{} is out of range: must be 10..=400", self.board_mhz)));
            }
            if self.led_shift.is_some_and(|s| s > 40) {
                return Err(Error::param("led-shift", "is out of range: must be 0..=40"));
            }
        }
        let scene = match &self.scene_dir {
            Some(_) if self.raygen => {
                return Err(Error::param("raygen", "needs the scene itself (an OBJ or --builtin), not --scene DIR"));
            }
            Some(_) if self.axis_frame => {
                return Err(Error::param(
                    "axis-frame",
                    "needs the scene itself (an OBJ or --builtin), not --scene DIR",
                ));
            }
            Some(dir) => GenScene::Folder(dir.clone()),
            None => GenScene::Scene {
                source: self.scene.source(),
                params: self.params.params()?,
                search: self.params.search(),
                raygen: (self.raygen || self.board.is_some()).then(|| self.camera.spec()),
            },
        };
        if self.axis_frame && self.raygen {
            return Err(Error::param(
                "axis-frame",
                "the core fed by its ray generator has no ray port: not with --raygen",
            ));
        }
        if !(1..=64).contains(&self.ray_id_width) {
            return Err(Error::param("ray-id-width", format!("{} is out of range: must be 1..=64", self.ray_id_width)));
        }
        crate::cores::clock::ClockTarget(self.target_mhz).check()?;
        check_folder(&self.out)?;
        let mem_spec = self.memory.spec()?;
        if self.memory.memory == super::args::MemoryPlace::External {
            for (name, given) in [("raygen", self.raygen), ("board", self.board.is_some())] {
                if given {
                    return Err(Error::param(name, "not with --memory external yet (docs/MEMORY.md)"));
                }
            }
        }
        Ok(GenConfig {
            memory: self.memory.memory,
            mem_spec,
            scene,
            out: self.out.clone(),
            vhdl: self.lang.contains(&Lang::Vhdl),
            verilog: self.lang.contains(&Lang::Verilog),
            ise: self.ise,
            debug_ports: self.debug_ports,
            measured: self.measured.clone(),
            target_mhz: self.target_mhz,
            ray_id_width: self.ray_id_width,
            bram_kbits: self.bram_kbits,
            div_bits: self.div_bits,
            threads: self.threads,
            axis_frame: self.axis_frame.then(|| self.camera.spec()),
            board: self.board.map(|board| BoardConfig {
                board,
                mhz: self.board_mhz,
                led_shift: self.led_shift,
                bitstream: board == crate::board::Board::Ulx3s && !self.no_bitstream,
                seed: self.pnr_seed,
            }),
        })
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct TestConfig {
    pub params: Params,
    pub scene: SceneSource,
    pub hw: HwArgs,
    pub sim: Simulation,
    /// Number of vectors, ≥ 1.
    pub vectors: usize,
    pub seed: u64,
    /// The HDL build folder (None for the Rust simulator).
    pub build: Option<PathBuf>,
}

impl TestArgs {
    pub fn config(&self) -> Result<TestConfig> {
        let params = self.params.params()?;
        // The slow simulators get fewer vectors by default.
        let vectors = self.vectors.unwrap_or(match self.sim {
            SimChoice::Rust | SimChoice::Verilator => 100_000,
            SimChoice::Iverilog | SimChoice::IverilogSv => 20_000,
            SimChoice::Ghdl => 2_000,
        });
        if vectors == 0 {
            return Err(Error::param("vectors", "0: nothing would run"));
        }
        refuse_core_shape(&self.hw.threads)?;
        let sim = Simulation::from(self.sim);
        Ok(TestConfig {
            params,
            scene: self.scene.source(),
            hw: self.hw.clone(),
            sim,
            vectors,
            seed: self.seed,
            build: sim.build_dir(&self.build, "target/fxrt-test")?,
        })
    }
}

/// `fxrt test` runs one intersection pipeline on vectors: the core's shape (slots, units,
/// pipelines, a device to fit) does not reach it, so a shape other than the default is refused
/// rather than ignored.
fn refuse_core_shape(t: &super::args::ThreadArgs) -> Result<()> {
    let what = "fxrt test checks the intersection pipeline alone; the core's shape is for fxrt sim, gen and synth";
    if let Some(d) = t.device {
        return Err(Error::param("device", format!("{}: {what}", d.name())));
    }
    let defaults = [
        ("slots", t.slots, crate::cores::top::DEFAULT_SLOTS),
        ("units", t.units, crate::cores::top::DEFAULT_UNITS),
        ("pipelines", t.pipelines, 1),
    ];
    match defaults.into_iter().find(|&(_, given, default)| given != default) {
        Some((name, given, _)) => Err(Error::param(name, format!("{given}: {what}"))),
        None => Ok(()),
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct SynthConfig {
    pub params: Params,
    /// What `--device`'s fit may choose of the scene's build.
    pub search: SceneSearch,
    pub scene: SceneSource,
    pub hw: HwArgs,
    pub build: PathBuf,
    pub family: Family,
    /// Where the scene lives (`auto` decided by `bram_kbits`) and the external core's caches.
    pub memory: super::args::MemoryPlace,
    pub mem_spec: crate::cores::memory_params::MemorySpec,
    pub bram_kbits: u64,
}

/// Where `fxrt synth` maps the cores.
#[derive(Clone, Debug, PartialEq)]
pub enum Family {
    /// Virtex-5 area from Debian's yosys.
    Xc5v,
    /// 7-series (Artix-7) area from Debian's yosys, a second reference.
    Xc7,
    /// LFE5U-85F place and route: the clock constraint, nextpnr's seeds, placer and the modules.
    Ecp5 { target_mhz: f64, seeds: Vec<u64>, placer: crate::fpga::ecp5::Placer, modules: Vec<String> },
}

impl Family {
    /// The family's part (the one its flow maps for).
    pub fn device(&self) -> Device {
        match self {
            Family::Ecp5 { .. } => Device::Lfe5u85f,
            Family::Xc5v => Device::Xc5vlx110t,
            Family::Xc7 => Device::Xc7a100t,
        }
    }

    /// The hard multiplier the cores synthesised for the family cut their products for: its
    /// part's.
    pub fn piece(&self) -> crate::cores::mul::Piece {
        self.device().piece()
    }
}

/// The modules `synth --family ecp5` (and `sweep --synth --family ecp5`) can place and route.
pub use crate::fpga::ecp5::MODULES as ECP5_MODULES;

impl SynthArgs {
    pub fn config(&self) -> Result<SynthConfig> {
        let family = match self.family.as_str() {
            "xc5v" => Family::Xc5v,
            "xc7" => Family::Xc7,
            "ecp5" => {
                crate::cores::clock::ClockTarget(self.hw.target_mhz).check()?;
                crate::fpga::ecp5::check_modules(&self.modules)?;
                let seeds = crate::fpga::ecp5::seeds::parse_seeds(&self.seeds)?;
                let placer = crate::fpga::ecp5::Placer::parse(&self.placer)?;
                Family::Ecp5 { target_mhz: self.hw.target_mhz as f64, seeds, placer, modules: self.modules.clone() }
            }
            other => {
                return Err(Error::param("family", format!("'{other}' is not supported: use xc5v, xc7 or ecp5")));
            }
        };
        if let Some(d) = self.hw.threads.device.filter(|d| d.family() != self.family) {
            let (name, own) = (d.name(), d.family());
            return Err(Error::param("device", format!("the {name} is mapped by --family {own}, not {}", self.family)));
        }
        let build = self.build.clone().unwrap_or_else(|| PathBuf::from("target/fxrt-synth"));
        check_folder(&build)?;
        // The family's part's (the XC7A100T's for xc7, not the XC5VLX110T's).
        let device_kbits = family.device().bram_kbits();
        Ok(SynthConfig {
            params: self.params.params()?,
            search: self.params.search(),
            scene: self.scene.source(),
            hw: self.hw.clone(),
            build,
            family,
            memory: self.memory.memory,
            mem_spec: self.memory.spec()?,
            bram_kbits: self.bram_kbits.unwrap_or(device_kbits),
        })
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct SimConfig {
    pub params: Params,
    /// What `--device`'s fit may choose of the scene's build.
    pub search: SceneSearch,
    pub scene: SceneSource,
    pub camera: CameraSpec,
    pub sim: Simulation,
    /// Rays from the on-chip ray generator instead of the host (Rust simulator only).
    pub raygen: bool,
    pub div_bits: u32,
    pub target_mhz: u32,
    pub threads: super::ThreadArgs,
    pub png: Option<PathBuf>,
    pub ids: Option<PathBuf>,
    /// The HDL build folder (None for the Rust simulator).
    pub build: Option<PathBuf>,
    /// A clock for the hardware speed: (MHz, from a measured Fmax).
    pub clock: Option<(f64, bool)>,
    /// Rays in this seed's random order (`feed::feed_order`); None: pixel order.
    pub shuffle_seed: Option<u64>,
    /// The source's stalls: (percent of cycles 1..=99, seed); None: it never stalls.
    pub stalls: Option<(u32, u64)>,
    /// Where the scene lives (`auto` decided by `bram_kbits`), the external core's options and
    /// its memory model, and the ray order.
    pub memory: super::args::MemoryPlace,
    pub bram_kbits: u64,
    pub mem_spec: crate::cores::memory_params::MemorySpec,
    pub mem_timing: crate::verify::memory::MemoryTiming,
    pub tiles: bool,
}

/// The clock of a `fxrt synth --family ecp5` JSON: the whole core's Fmax, else the slowest
/// module's.
pub fn fmax_of(path: &std::path::Path) -> Result<f64> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::file(path, e.to_string()))?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| Error::file(path, e.to_string()))?;
    let modules =
        v["modules"].as_array().ok_or_else(|| Error::file(path, "no \"modules\": not a synth --family ecp5 JSON"))?;
    let placed = modules.iter().map(|m| (m["module"].as_str().unwrap_or(""), m["fmax_mhz"].as_f64().unwrap_or(0.0)));
    crate::fpga::ecp5::core_clock(placed).ok_or_else(|| Error::file(path, "no module with an fmax_mhz"))
}

impl SimArgs {
    pub fn config(&self) -> Result<SimConfig> {
        let params = self.params.params()?;
        let sim = Simulation::from(self.sim);
        check_outputs(&[("png", &self.png), ("ids", &self.ids)])?;
        if self.raygen && sim != Simulation::Rust {
            return Err(Error::param("raygen", "runs in the Rust simulator only (--sim rust)"));
        }
        let max = crate::verify::feed::Stalls::MAX_PERCENT;
        if self.stall_percent > max {
            return Err(Error::param(
                "stall-percent",
                format!("{} is out of range: must be 0..={max} (at 100 no ray is ever offered)", self.stall_percent),
            ));
        }
        if self.stall_seed.is_some() && self.stall_percent == 0 {
            return Err(Error::param("stall-seed", "seeds the stalls of --stall-percent: add --stall-percent"));
        }
        let (mem_spec, mem_timing) = self.external.spec()?;
        let tiles = self.external.ray_order == super::args::RayOrder::Tiles;
        if tiles && self.shuffle_seed.is_some() {
            return Err(Error::param("ray-order", "tiles is an order of its own: not with --shuffle-seed"));
        }
        // The ray generator feeds the core itself, in pixel order, whenever it is ready.
        for (given, name) in [
            (self.shuffle_seed.is_some(), "shuffle-seed"),
            (self.stall_percent > 0, "stall-percent"),
            (tiles, "ray-order"),
        ] {
            if given && self.raygen {
                return Err(Error::param(name, "feeds host rays: not with --raygen (the generator feeds the core)"));
            }
        }
        Ok(SimConfig {
            params,
            search: self.params.search(),
            scene: self.scene.source(),
            camera: self.camera.spec(),
            sim,
            raygen: self.raygen,
            div_bits: self.div_bits,
            target_mhz: self.target_mhz,
            threads: self.threads,
            png: self.png.clone(),
            ids: self.ids.clone(),
            build: sim.build_dir(&self.build, "target/fxrt-sim")?,
            clock: match (self.clock_mhz, &self.fmax_json) {
                (Some(f), _) if !(f.is_finite() && f > 0.0) => {
                    return Err(Error::param("clock-mhz", format!("{f} is out of range: must be > 0")));
                }
                (Some(f), _) => Some((f, false)),
                (None, Some(path)) => Some((fmax_of(path)?, true)),
                (None, None) => None,
            },
            shuffle_seed: self.shuffle_seed,
            stalls: (self.stall_percent > 0).then(|| (self.stall_percent, self.stall_seed.unwrap_or(1))),
            memory: self.external.core.memory,
            bram_kbits: self.bram_kbits,
            mem_spec,
            mem_timing,
            tiles: self.external.ray_order == super::args::RayOrder::Tiles,
        })
    }
}

impl ParamArgs {
    pub fn params(&self) -> Result<Params> {
        let d = Params::default();
        let p = Params {
            n: self.n,
            m: self.m,
            edge_shift: self.edge_shift,
            t: self.t,
            c: self.c,
            leaf_size: self.leaf_size.unwrap_or(d.leaf_size),
            stack_depth: self.stack_depth.unwrap_or(d.stack_depth),
            tree: self.tree,
            sah_step_percent: self.sah_step_percent.unwrap_or(d.sah_step_percent),
        };
        p.validate()?;
        Ok(p)
    }

    /// What `--device`'s fit may choose of the scene's build: what was not given.
    pub fn search(&self) -> SceneSearch {
        SceneSearch {
            leaf_size: self.leaf_size.is_none(),
            stack_depth: self.stack_depth.is_none(),
            sah_step: self.sah_step_percent.is_none(),
        }
    }
}

impl SceneChoice {
    /// The embedded teapot when neither a file nor a built-in is named.
    pub fn source(&self) -> SceneSource {
        match (&self.scene, &self.builtin) {
            (Some(p), _) => SceneSource::Obj(p.clone()),
            (None, Some(b)) => SceneSource::Builtin(b.clone()),
            (None, None) => SceneSource::Builtin("teapot".into()),
        }
    }
}

impl CameraArgs {
    pub fn spec(&self) -> CameraSpec {
        let (width, height) = self.size;
        CameraSpec { eye: self.eye, at: self.at, up: self.up, fov: self.fov, width, height }
    }
    pub fn camera(&self, scene: &crate::scene::Scene) -> Result<Camera> {
        self.spec().camera(scene)
    }
}
