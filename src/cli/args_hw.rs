//! The arguments of the hardware commands (demo, gen, test, synth, sim, sweep), as clap parses
//! them.

use super::args::{CameraArgs, FrameSim, HwArgs, ParamArgs, SceneChoice, ThreadArgs, parse_percent, parse_size};
use crate::params::TreeSplit;
use clap::{Args, Subcommand};
use std::path::PathBuf;

/// `fxrt demo` (and `fxrt` with no arguments).
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder: hdl/ (the core's files), golden.png, hardware.png.
    #[arg(long, default_value = "fxrt-out")]
    pub out: PathBuf,
    /// The simulated frame, WxH (at most 256x256).
    #[arg(long, value_parser = parse_size, default_value = "128x128")]
    pub size: (u32, u32),
    /// Where the core keeps the teapot: onchip, external (behind an AXI4 read port and on-chip
    /// caches at their defaults; the frame then runs against the memory model at L = 40) or
    /// auto (on chip when it fits the LFE5U-85F's block RAM, as the teapot does).
    #[arg(long, value_enum, default_value = "auto")]
    pub memory: super::args::MemoryPlace,
    /// Fit the core's slots, units and pipelines to this device (as `gen --device`), and
    /// count its block RAM for `--memory auto`; the default core and the LFE5U-85F without it.
    #[arg(long, value_enum)]
    pub device: Option<crate::fpga::device::Device>,
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
    /// Traversal units U (1..=8).
    #[arg(long, default_value_t = crate::cores::top::DEFAULT_UNITS.to_string())]
    pub units: String,
    /// Fit every core's slots, units and intersection pipelines to this device (as `gen
    /// --device`), once: on the first scene at the base set, at the leaf size and stack given.
    #[arg(long, value_enum, conflicts_with_all = ["slots", "units"])]
    pub device: Option<crate::fpga::device::Device>,
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
    #[command(flatten)]
    pub memory: SweepMemoryArgs,
}

/// `fxrt sweep --memory external`: the memory's latency and the caches' sizes as lists.
#[derive(Args, Debug)]
pub struct SweepMemoryArgs {
    /// Where every core keeps its scene: onchip, or external (behind an AXI4 read port and
    /// on-chip caches; the lists below become axes).
    #[arg(long, value_enum, default_value = "onchip")]
    pub memory: super::args::MemoryPlace,
    /// --memory external: the memory model's latency, clocks (1..=1000; list).
    #[arg(long = "mem-latency")]
    pub mem_latency: Option<String>,
    /// --memory external: each traversal unit's node cache, KB (list).
    #[arg(long = "node-cache-kb")]
    pub node_cache_kb: Option<String>,
    /// --memory external: the triangle cache, KB (list).
    #[arg(long = "tri-cache-kb")]
    pub tri_cache_kb: Option<String>,
    #[command(flatten)]
    pub shape: super::args::MemoryArgs,
    /// --memory external: ways of each cache: 1, 2 or 4.
    #[arg(long = "cache-ways", default_value_t = crate::cores::memory_params::DEFAULT_WAYS)]
    pub cache_ways: u32,
    /// --memory external: feed rays in pixel order or in 8 × 8 tiles.
    #[arg(long = "ray-order", value_enum, default_value = "pixels")]
    pub ray_order: super::args::RayOrder,
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
    pub external: super::args::ExternalArgs,
    /// Block RAM the scene's ROMs may take, Kb (--memory auto: external when they do not fit).
    #[arg(long = "bram-kbits", default_value_t = 5328)]
    pub bram_kbits: u64,
    #[command(flatten)]
    pub params: ParamArgs,
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
    /// ecp5: nextpnr's placement seeds — one (`3`), a range (`1..5`) or a list (`1,4,9`): the
    /// netlist is synthesised once and placed at each seed (as many at once as the machine has
    /// cores); the report gives the median seed's figures and the spread.
    #[arg(long = "seeds", visible_alias = "seed", default_value = "1")]
    pub seeds: String,
    /// ecp5: nextpnr-ecp5's placer, heap (its default; the clock figures) or static
    /// (electrostatic: routes the fitted four-unit core in about an hour, but at 102–116 MHz
    /// against HeAP's 131; DECISIONS 143).
    #[arg(long, default_value = "heap")]
    pub placer: String,
    /// ecp5: which modules to place and route (each takes minutes; the whole core is the
    /// longest): any of divider, intersect, traverse, closest, core.
    #[arg(long, value_delimiter = ',', default_value = "divider,intersect,traverse,closest,core")]
    pub modules: Vec<String>,
    /// Folder for the netlists and yosys logs. Default: target/fxrt-synth.
    #[arg(long)]
    pub build: Option<PathBuf>,
    #[command(flatten)]
    pub memory: super::args::CoreMemoryArgs,
    /// Block RAM the scene's ROMs (or the caches) may take, Kb. Default: the family's device
    /// (ecp5: the LFE5U-85F's 208 DP16KD, 3744; xc5v and xc7: the XC5VLX110T's 5328).
    #[arg(long = "bram-kbits")]
    pub bram_kbits: Option<u64>,
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
    #[command(flatten)]
    pub memory: super::args::CoreMemoryArgs,
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
