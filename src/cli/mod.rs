//! The command line, in three layers: clap structs parsed with no side effects (here), each
//! command's arguments validated into a configuration before anything runs or any file is
//! written (`config`), and the commands run on those (`run`). `main.rs` only dispatches.

pub mod bench_embree;
pub mod board;
pub mod config;
pub mod demo;
pub mod exact;
pub mod run;
pub mod sweep_config;

use crate::params::{EdgeShift, TreeSplit};
use crate::render::tracer::ModelKind;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(
    name = "fxrt",
    version,
    about = "Fixed-point hardware ray tracing: scene ROMs, a bit-exact golden model, float references and renders"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

impl Cli {
    /// The command given, or the main job on the embedded default: `fxrt demo` (the core
    /// generated for the teapot, a frame simulated and checked, both pictures, into fxrt-out/).
    pub fn command_or_default(self) -> Command {
        self.command.unwrap_or_else(|| {
            let job = Cli::parse_from(["fxrt", "demo"]);
            job.command.expect("the default job is a command")
        })
    }
}

/// A clap error as one line, like every other input error (`--help` has the details).
pub fn error_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    text.lines().next().unwrap_or("invalid arguments").trim_start_matches("error: ").to_string()
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// The whole product on the embedded teapot (what `fxrt` alone runs): the core generated
    /// in VHDL and Verilog with its ROMs and manifest, a frame through it in the Rust
    /// simulator checked pixel by pixel against the golden model, both pictures, a summary.
    Demo(DemoArgs),
    /// Render a scene through a model (golden integer, f64, f32 or watertight).
    Render(RenderArgs),
    /// Quantise a scene, build its BIH and write the ROM images and scene.json.
    Scene(SceneArgs),
    /// Count where the golden model and a float reference disagree on a frame.
    Compare(CompareArgs),
    /// Measure golden-model render speed (teapot, primary rays).
    Bench(BenchArgs),
    /// Generate the HDL cores (VHDL-93, Verilog-2001) and their JSON manifests.
    Gen(GenArgs),
    /// Check the intersection pipeline against the golden model in a simulator.
    Test(TestArgs),
    /// Virtex-5 area of the cores from yosys (LUT, FF, DSP48E, BRAM), as JSON.
    Synth(SynthArgs),
    /// Run a whole frame through the generated ray tracing core and compare every pixel.
    Sim(SimArgs),
    /// Image error and hardware cost over lists of n, m, T, C and E: each takes values
    /// `12,16`, ranges `20..29` (inclusive) or steps `0..24:8`; `sweep merge` joins shards.
    Sweep(SweepArgs),
}

/// `fxrt demo` (and `fxrt` with no arguments).
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder: hdl/ (the core's files), golden.png, hardware.png.
    #[arg(long, default_value = "fxrt-out")]
    pub out: PathBuf,
    /// The simulated frame, WxH (at most 256x256).
    #[arg(long, value_parser = parse_size, default_value = "128x128")]
    pub size: (u32, u32),
}

impl DemoArgs {
    pub fn config(&self) -> crate::error::Result<demo::DemoConfig> {
        let (width, height) = self.size;
        demo::check_size(width, height)?;
        crate::io::check_folder(&self.out)?;
        Ok(demo::DemoConfig { out: self.out.clone(), width, height })
    }
}

/// `fxrt sweep`: every parameter takes a list (`12,16,20`), a range (`20..29`, inclusive) or a
/// range with a step (`0..24:8`), mixed freely.
#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct SweepArgs {
    #[command(subcommand)]
    pub action: Option<SweepAction>,
    /// OBJ files to sweep (before the built-ins).
    pub scenes: Vec<PathBuf>,
    /// Built-in scenes: teapot, teapot-fine, jackstraws, thin, random, cornell (comma-separated
    /// or repeated). Default: teapot, when no OBJ file is named either.
    #[arg(long, value_delimiter = ',')]
    pub builtin: Vec<String>,
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Vertex grid bits n (4..=40).
    #[arg(long, default_value = "29")]
    pub n: String,
    /// Fixed-point bits m (8..=64).
    #[arg(long, default_value = "32")]
    pub m: String,
    /// Division precision drop T (0..=m−2).
    #[arg(long, default_value = "0")]
    pub t: String,
    /// Reciprocal-direction extra bits C.
    #[arg(long, default_value = "16")]
    pub c: String,
    /// Edge shift E: 'auto' and/or values.
    #[arg(long = "edge-shift", default_value = "auto")]
    pub edge_shift: String,
    /// Largest number of triangles in a BIH leaf (1..=64).
    #[arg(long = "leaf-size", default_value = "4")]
    pub leaf_size: String,
    /// Hardware traversal stack entries (one value).
    #[arg(long = "stack-depth", default_value_t = 32)]
    pub stack_depth: u32,
    /// The BIH's split planes: middle (the thesis's) or sah (binned surface-area heuristic);
    /// one value.
    #[arg(long, default_value = "sah")]
    pub tree: TreeSplit,
    /// Ray slots per traversal unit K: the rays each unit holds at once (1..=64).
    #[arg(long, default_value_t = crate::cores::top::DEFAULT_SLOTS.to_string())]
    pub slots: String,
    /// Traversal units U feeding the one intersection pipeline (1..=4).
    #[arg(long, default_value_t = crate::cores::top::DEFAULT_UNITS.to_string())]
    pub units: String,
    /// Vary one parameter at a time around the base set (each at its default if listed,
    /// else its first value), like the thesis's figures, instead of the cross product.
    #[arg(long = "one-at-a-time")]
    pub one_at_a_time: bool,
    /// Also synthesise each configuration's core with yosys for Virtex-5 (slow).
    #[arg(long)]
    pub synth: bool,
    /// With --synth: xc5v (Virtex-5 area from Debian's yosys; the default) or ecp5 (each
    /// configuration's --modules placed and routed on the LFE5U-85F with yosys and
    /// nextpnr-ecp5 from the project's .venv: Fmax, critical path, resources).
    #[arg(long)]
    pub family: Option<String>,
    /// The clock the cores are pipelined for, MHz (50..=400): it sets their latencies; with
    /// --family ecp5 also nextpnr's constraint.
    #[arg(long = "target-mhz", default_value_t = crate::cores::clock::DEFAULT_TARGET_MHZ)]
    pub target_mhz: u32,
    /// --family ecp5: nextpnr's placement seed (default 1).
    #[arg(long)]
    pub seed: Option<u64>,
    /// --family ecp5: which modules of each configuration's core to place and route (the
    /// whole core takes minutes to a quarter of an hour): any of divider, intersect,
    /// traverse, closest, core. Default: core.
    #[arg(long, value_delimiter = ',')]
    pub modules: Option<Vec<String>>,
    /// Also run each configuration's frame through the whole core in the Rust simulator:
    /// cycles per ray, pipeline fill, stack depth, and every pixel against the golden model
    /// (slow; use small sizes).
    #[arg(long = "core-sim")]
    pub core_sim: bool,
    /// Output folder (it also caches finished configurations for reruns).
    #[arg(long, required_unless_present = "action")]
    pub out: Option<PathBuf>,
    /// Cache folder for finished configurations. Default: OUT/cache. Shards of one sweep may
    /// share one (writes are atomic), so a rerun with other lists or shard counts reuses all.
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Compute only shard I of N: the configurations whose index mod N is I − 1.
    #[arg(long, value_parser = crate::sweep::Shard::parse)]
    pub shard: Option<crate::sweep::Shard>,
    /// Write a Slurm job-array script, a merge job and a GNU parallel command list into
    /// OUT/slurm instead of running.
    #[arg(long = "emit-slurm")]
    pub emit_slurm: bool,
    /// Shards for --emit-slurm (at most 1000, Slurm's default array limit).
    #[arg(long, default_value_t = 8)]
    pub shards: u32,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

#[derive(Subcommand, Debug)]
pub enum SweepAction {
    /// Join the folders of a sweep's shards into one.
    Merge(SweepMergeArgs),
}

#[derive(Args, Debug)]
pub struct SweepMergeArgs {
    /// The shard folders.
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Cache folder the shards shared (where a shard folder has no cache of its own), and
    /// the merged sweep's cache. Default: OUT/cache.
    #[arg(long)]
    pub cache: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct SimArgs {
    #[command(flatten)]
    pub scene: SceneChoice,
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Where the core runs.
    #[arg(long, value_enum, default_value = "rust")]
    pub sim: FrameSim,
    /// Write W·H little-endian i32: input triangle number per pixel, −1 for a miss (as `render`).
    #[arg(long)]
    pub ids: Option<PathBuf>,
    /// Write the binary hit/miss picture the core produced (seed 001 figure 3.7).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Build folder for an HDL simulation. Default: target/fxrt-sim/SIM.
    #[arg(long)]
    pub build: Option<PathBuf>,
    /// Quotient bits per divider stage: 1 or 2.
    #[arg(long = "div-bits", default_value_t = 1)]
    pub div_bits: u32,
    /// The clock the cores are pipelined for, MHz (50..=400): it sets their latencies.
    #[arg(long = "target-mhz", default_value_t = crate::cores::clock::DEFAULT_TARGET_MHZ)]
    pub target_mhz: u32,
    #[command(flatten)]
    pub threads: ThreadArgs,
    /// Use the on-chip pinhole ray generator (camera inside the scene box) instead of host rays.
    #[arg(long)]
    pub raygen: bool,
    /// A clock to report hardware speed at: `mrays_per_s_at_clock` = clock / cycles per ray.
    #[arg(long = "clock-mhz", conflicts_with = "fmax_json")]
    pub clock_mhz: Option<f64>,
    /// A `fxrt synth --family ecp5` JSON: its whole core's Fmax (or else its slowest module's)
    /// is the clock, reported as `mrays_per_s_at_fmax`.
    #[arg(long = "fmax-json", value_name = "FILE")]
    pub fmax_json: Option<PathBuf>,
    /// Feed the rays in a random order, this seed's permutation, instead of pixel order
    /// (results are matched to rays by id, in any order).
    #[arg(long = "shuffle-seed", value_name = "SEED", allow_hyphen_values = true)]
    pub shuffle_seed: Option<u64>,
    /// Hold the ray source back (ray_valid low, rays left) on this percentage of cycles,
    /// 0..=99, at random (seeded by --stall-seed).
    #[arg(long = "stall-percent", value_name = "P", default_value_t = 0, allow_hyphen_values = true, value_parser = parse_percent)]
    pub stall_percent: u32,
    /// Seed of the stall pattern of --stall-percent.
    #[arg(long = "stall-seed", value_name = "SEED", allow_hyphen_values = true)]
    pub stall_seed: Option<u64>,
    #[command(flatten)]
    pub params: ParamArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FrameSim {
    Rust,
    Ghdl,
    Verilator,
}

#[derive(Args, Debug)]
pub struct SynthArgs {
    /// The scene the whole core holds in its ROMs (and whose E the pipeline uses).
    #[command(flatten)]
    pub scene: SceneChoice,
    /// Target family: xc5v (Virtex-5 area from Debian's yosys), xc7 (7-series area, the same
    /// way) or ecp5 (LFE5U-85F place and route with yosys and nextpnr-ecp5 from the project's
    /// .venv: Fmax, critical path, resources).
    #[arg(long, default_value = "xc5v")]
    pub family: String,
    /// ecp5: nextpnr's placement seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// ecp5: which modules to place and route (each takes minutes; the whole core is the
    /// longest): any of divider, intersect, traverse, closest, core.
    #[arg(long, value_delimiter = ',', default_value = "divider,intersect,traverse,closest,core")]
    pub modules: Vec<String>,
    /// Folder for the netlists and yosys logs. Default: target/fxrt-synth.
    #[arg(long)]
    pub build: Option<PathBuf>,
    #[command(flatten)]
    pub hw: HwArgs,
    #[command(flatten)]
    pub params: ParamArgs,
}

#[derive(Args, Debug)]
pub struct GenArgs {
    /// The scene the core is built for: its ROMs, box and edge shift E.
    #[command(flatten)]
    pub scene: SceneChoice,
    /// A folder written by `fxrt scene`: build the core from its scene.json and ROM images
    /// (the parameters are the ones stored there).
    #[arg(long = "scene", value_name = "DIR", conflicts_with_all = ["scene", "builtin"])]
    pub scene_dir: Option<PathBuf>,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// Languages to write.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "vhdl,verilog")]
    pub lang: Vec<Lang>,
    /// Also write an ISE project script (xtclsh) and a UCF for the XC5VLX110T-1FF1136.
    #[arg(long)]
    pub ise: bool,
    /// Also give the core its observation ports (busy, stack_depth, visits, culls, occupied,
    /// accept*, visit*: docs/CORE.md), which the simulations count with.
    #[arg(long = "debug-ports")]
    pub debug_ports: bool,
    /// A report of `fxrt synth --family ecp5` for this scene and parameters: its measured clock
    /// and resources go into the core's manifest.
    #[arg(long, value_name = "FILE")]
    pub measured: Option<PathBuf>,
    /// The clock the cores are pipelined for, MHz (50..=400); also the ISE UCF's constraint.
    #[arg(long = "target-mhz", default_value_t = crate::cores::clock::DEFAULT_TARGET_MHZ)]
    pub target_mhz: u32,
    #[command(flatten)]
    pub threads: ThreadArgs,
    /// Width of the ray id port (rays in flight are numbered modulo 2^width).
    #[arg(long = "ray-id-width", default_value_t = 20)]
    pub ray_id_width: u32,
    /// Block RAM the ROMs may use, kilobits (default: the XC5VLX110T's 148 × 36 Kb).
    #[arg(long = "bram-kbits", default_value_t = 5328)]
    pub bram_kbits: u64,
    /// Quotient bits per divider stage: 1 or 2.
    #[arg(long = "div-bits", default_value_t = 1)]
    pub div_bits: u32,
    /// Build `fxrt_core_raygen`: the core fed by an on-chip pinhole ray generator for the
    /// camera given by --eye/--at/--up/--fov/--size (the eye must be inside the scene box).
    #[arg(long)]
    pub raygen: bool,
    /// Build a board top instead of the core's files (docs/BOARDS.md): the on-chip ray
    /// generator → the core → a checksum of every result, checked against the golden model's
    /// at each frame's end and shown on the LEDs, with the PLL, reset and pins. ulx3s also
    /// places, routes and packs the bitstream (the ECP5 tools in .venv); ml509 writes the ISE
    /// project that does. The camera: --eye/--at/... inside the scene box (default: at the
    /// middle of the box's front, looking at its centre).
    #[arg(long, value_enum)]
    pub board: Option<crate::board::Board>,
    /// --board: the board clock, MHz; the PLL makes the fastest clock not above it.
    #[arg(long = "board-mhz", default_value_t = 80.0)]
    pub board_mhz: f64,
    /// --board: the frame counter bit LED 2 shows (default: one the eye can follow).
    #[arg(long = "led-shift")]
    pub led_shift: Option<u32>,
    /// --board ulx3s: the HDL and constraints only, no place and route.
    #[arg(long = "no-bitstream")]
    pub no_bitstream: bool,
    /// --board ulx3s: nextpnr's placement seed.
    #[arg(long = "pnr-seed", default_value_t = 1)]
    pub pnr_seed: u64,
    /// Also write the frame of --size (and the other camera options) for the AXI4-Stream
    /// wrapper: rays.bin, each ray's tdata in pixel order, and expected.bin, the golden model's
    /// result tdata for each, in the same order (docs/AXIS.md). Only the rays that reach the
    /// scene's box are in it: their ids, the pixel numbers, have gaps.
    #[arg(long = "axis-frame")]
    pub axis_frame: bool,
    #[command(flatten)]
    pub camera: CameraArgs,
    #[command(flatten)]
    pub params: ParamArgs,
}

/// The core's ray slots and traversal units (docs/CORE.md): how many rays it holds at once.
#[derive(Args, Debug, Clone, Copy, PartialEq, Eq)]
pub struct ThreadArgs {
    /// Ray slots per traversal unit: the rays each unit holds at once (1..=64).
    #[arg(long, default_value_t = crate::cores::top::DEFAULT_SLOTS)]
    pub slots: u32,
    /// Traversal units feeding the one intersection pipeline (1..=4).
    #[arg(long, default_value_t = crate::cores::top::DEFAULT_UNITS)]
    pub units: u32,
}

/// Choices of the hardware that do not change the arithmetic.
#[derive(Args, Debug, Clone, PartialEq, Eq)]
pub struct HwArgs {
    /// Width of the tag passed through the intersection pipeline (1..=64).
    #[arg(long = "tag-width", default_value_t = 32)]
    pub tag_width: u32,
    /// Quotient bits per divider stage: 1 (latency n + 2) or 2 (latency 1 + ⌈(n+1)/2⌉).
    #[arg(long = "div-bits", default_value_t = 1)]
    pub div_bits: u32,
    /// The clock the cores are pipelined for, MHz (50..=400); `synth --family ecp5` also
    /// constrains nextpnr to it.
    #[arg(long = "target-mhz", default_value_t = crate::cores::clock::DEFAULT_TARGET_MHZ)]
    pub target_mhz: u32,
    #[command(flatten)]
    pub threads: ThreadArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Lang {
    Vhdl,
    Verilog,
}

#[derive(Args, Debug)]
pub struct TestArgs {
    /// The scene the vectors are drawn from (and whose E the pipeline uses).
    #[command(flatten)]
    pub scene: SceneChoice,
    /// Where the pipeline runs: the Rust simulator or an HDL simulator.
    #[arg(long, value_enum, default_value = "rust")]
    pub sim: SimChoice,
    /// Number of (ray, triangle) vectors. Default: 100,000 (rust, verilator), 2,000 (ghdl), 20,000 (iverilog).
    #[arg(long)]
    pub vectors: Option<usize>,
    /// Build folder for the HDL, testbench and vectors. Default: target/fxrt-test/SIM.
    #[arg(long)]
    pub build: Option<PathBuf>,
    /// Seed of the random vectors.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[command(flatten)]
    pub hw: HwArgs,
    #[command(flatten)]
    pub params: ParamArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SimChoice {
    Rust,
    Ghdl,
    /// Icarus under Verilog-2005 rules.
    Iverilog,
    /// Icarus under SystemVerilog rules (-g2012, as cocotb runs it).
    #[value(name = "iverilog-sv")]
    IverilogSv,
    Verilator,
}

/// The parameter set (seed 001 §2.1–2.4), shared by every subcommand.
#[derive(Args, Debug, Clone)]
pub struct ParamArgs {
    /// Vertex grid bits: the longest scene side maps to 2^n − 1 (4..=40).
    #[arg(long, default_value_t = 29)]
    pub n: u32,
    /// Bits of fixed-point vectors in [−1, 1]: normals, edges, directions (8..=64).
    #[arg(long, default_value_t = 32)]
    pub m: u32,
    /// Edge shift E: 'auto' (scene-adaptive, seed 003) or an integer (the thesis used 10).
    #[arg(long = "edge-shift", default_value = "auto", allow_hyphen_values = true)]
    pub edge_shift: EdgeShift,
    /// Division precision drop T: numerator and denominator lose T low bits (0..=m−2).
    #[arg(long, default_value_t = 0)]
    pub t: u32,
    /// Extra bits C of the reciprocal ray direction (m+C bits) used in BIH traversal.
    #[arg(long, default_value_t = 16)]
    pub c: u32,
    /// Largest number of triangles in a BIH leaf.
    #[arg(long = "leaf-size", default_value_t = 4)]
    pub leaf_size: u32,
    /// Hardware traversal stack entries; bounds the BIH depth.
    #[arg(long = "stack-depth", default_value_t = 32)]
    pub stack_depth: u32,
    /// The BIH's split planes: middle (the thesis's: halve the box) or sah (binned
    /// surface-area heuristic).
    #[arg(long, default_value = "sah")]
    pub tree: TreeSplit,
}

#[derive(Args, Debug, Clone)]
pub struct SceneChoice {
    /// An OBJ file (polygons are fan-triangulated, numbered in file order).
    pub scene: Option<PathBuf>,
    /// A built-in scene instead of a file: teapot, jackstraws, thin, random, cornell.
    #[arg(long, conflicts_with = "scene")]
    pub builtin: Option<String>,
}

#[derive(Args, Debug, Clone)]
pub struct CameraArgs {
    /// Eye position X,Y,Z (world units). Default: a view framing the whole scene.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<[f64; 3]>,
    /// Look-at point X,Y,Z. Default: the scene's centre.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub at: Option<[f64; 3]>,
    /// Up vector X,Y,Z.
    #[arg(long, value_parser = parse_vec3, default_value = "0,1,0", allow_hyphen_values = true)]
    pub up: [f64; 3],
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 45.0)]
    pub fov: f64,
    /// Image size WxH.
    #[arg(long, value_parser = parse_size, default_value = "256x256")]
    pub size: (u32, u32),
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneChoice,
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Which model computes the intersections.
    #[arg(long, value_enum, default_value = "golden")]
    pub model: ModelKind,
    /// Write a picture.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Write W·H little-endian i32: input triangle number per pixel, −1 for a miss.
    #[arg(long)]
    pub ids: Option<PathBuf>,
    /// Write W·H little-endian f32: world distance from the eye, +inf for a miss.
    #[arg(long)]
    pub depth: Option<PathBuf>,
    /// Shade with one shadow ray per hit towards a point light near the eye.
    #[arg(long)]
    pub shade: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub params: ParamArgs,
}

#[derive(Args, Debug)]
pub struct SceneArgs {
    #[command(flatten)]
    pub scene: SceneChoice,
    /// Output directory for the ROM images and scene.json.
    #[arg(long)]
    pub out: PathBuf,
    /// Also print statistics and the edge-component histogram (seed 001 figure 2.1).
    #[arg(long)]
    pub stats: bool,
    #[command(flatten)]
    pub params: ParamArgs,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    #[command(flatten)]
    pub scene: SceneChoice,
    #[command(flatten)]
    pub camera: CameraArgs,
    /// The reference the golden model is compared with.
    #[arg(long, value_enum, default_value = "f64")]
    pub against: ModelKind,
    #[arg(long)]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub params: ParamArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BenchWhat {
    /// Golden-model render speed: teapot, primary rays, Mrays/s.
    Render,
    /// Simulator speed on the intersection pipeline: Rust, Verilator and GHDL, cycles/s.
    Sim,
    /// The agreement property at length: `--netlists` random netlists, cycle simulator
    /// against batched simulator, every output of every cycle (exit 1 on a difference).
    Agree,
    /// The differential campaign: random scenes, parameters, core shapes, cameras and feeds,
    /// every ray through the core in the Rust simulator against the golden model, for
    /// `--seconds`; the first disagreement is written as a reproducer (exit 1).
    Exact,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// What to measure.
    #[arg(value_enum, default_value = "render")]
    pub what: BenchWhat,
    /// Vectors for `bench sim` (the same ones for every simulator; GHDL runs a prefix).
    #[arg(long, default_value_t = 200_000)]
    pub vectors: usize,
    /// How many of those vectors GHDL runs.
    #[arg(long = "ghdl-vectors", default_value_t = 3000)]
    pub ghdl_vectors: usize,
    /// Random netlists for `bench agree` (seeds 0 … N − 1; the test suite runs 10,000).
    #[arg(long, default_value_t = 1_000_000)]
    pub netlists: u64,
    /// Image size WxH.
    #[arg(long, value_parser = parse_size, default_value = "1024x1024")]
    pub size: (u32, u32),
    /// Worker threads. Default: 1; with --against-embree, 1 and then all cores (this many
    /// instead of all).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Repetitions; the best is reported.
    #[arg(long, default_value_t = 3)]
    pub repeat: u32,
    /// Trace the same camera's rays in Embree (the Python package embreex in .venv) in the
    /// same run, one thread and all threads, for two views (framing and distant): both
    /// throughputs and their ratio (docs/PERFORMANCE.md).
    #[arg(long = "against-embree")]
    pub against_embree: bool,
    /// `bench exact`: draw new cases for this many seconds.
    #[arg(long, default_value_t = 60.0)]
    pub seconds: f64,
    /// `bench exact`: at most this many cases (and at most --seconds).
    #[arg(long)]
    pub cases: Option<u64>,
    /// `bench exact`: the campaign's seed; case k is a function of it and k alone.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// `bench exact`: a folder whose .obj files are drawn from too (e.g. ../shared/scenes).
    #[arg(long, value_name = "DIR")]
    pub scenes: Option<PathBuf>,
    /// `bench exact`: where the first disagreement's reproducer is written.
    #[arg(long, default_value = "fxrt-exact")]
    pub out: PathBuf,
    /// `bench exact`: run cases in this HDL simulator too (ghdl or verilator), every
    /// --hdl-every-th case: the same results in the same order and cycles as the Rust simulator.
    #[arg(long, value_enum)]
    pub hdl: Option<FrameSim>,
    /// `bench exact`: with --hdl, cases 0, K, 2K, … run in the HDL simulator (each takes a
    /// minute or more there).
    #[arg(long = "hdl-every", value_name = "K", default_value_t = 10)]
    pub hdl_every: u64,
}

fn parse_vec3(s: &str) -> std::result::Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 3 {
        return Err(format!("'{s}' is not X,Y,Z"));
    }
    let mut v = [0.0; 3];
    for (k, p) in parts.iter().enumerate() {
        v[k] = p.trim().parse::<f64>().map_err(|_| format!("'{p}' is not a number"))?;
        if !v[k].is_finite() {
            return Err(format!("'{p}' is not a finite number"));
        }
    }
    Ok(v)
}

/// A stall percentage: 0..=`Stalls::MAX_PERCENT`.
fn parse_percent(s: &str) -> std::result::Result<u32, String> {
    let max = crate::verify::feed::Stalls::MAX_PERCENT;
    let p: u32 = s.trim().parse().map_err(|_| format!("'{s}' is not an integer 0..={max}"))?;
    if p > max {
        return Err(format!("{p} is out of range: must be 0..={max} (at 100 no ray is ever offered)"));
    }
    Ok(p)
}

fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("'{s}' is not WxH"))?;
    let w: u32 = w.parse().map_err(|_| format!("'{w}' is not a positive integer"))?;
    let h: u32 = h.parse().map_err(|_| format!("'{h}' is not a positive integer"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("{w}x{h} is out of range: each side must be 1..=16384"));
    }
    Ok((w, h))
}

#[cfg(test)]
mod tests;
