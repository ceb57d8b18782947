//! The arguments every command shares (parameters, scene, camera, threads, hardware widths)
//! and those of the software commands (render, scene, compare, bench), as clap parses them.

use crate::params::{EdgeShift, TreeSplit};
use crate::render::tracer::ModelKind;
use clap::Args;
use std::path::PathBuf;

/// The core's ray slots, traversal units and intersection pipelines (docs/CORE.md), or the
/// device to fit them to.
#[derive(Args, Debug, Clone, Copy, PartialEq, Eq)]
pub struct ThreadArgs {
    /// Ray slots per traversal unit: the rays each unit holds at once (1..=64).
    #[arg(long, default_value_t = crate::cores::top::DEFAULT_SLOTS)]
    pub slots: u32,
    /// Traversal units (1..=8).
    #[arg(long, default_value_t = crate::cores::top::DEFAULT_UNITS)]
    pub units: u32,
    /// Intersection pipelines (1, 2 or 4, dividing --units): each serves --units / P units.
    #[arg(long, default_value_t = 1)]
    pub pipelines: u32,
    /// Fit the slots, units and pipelines to this device: of the shapes whose multipliers and
    /// block RAM it holds, the one with the most rays per clock on a short frame of the scene.
    #[arg(long, value_enum, conflicts_with_all = ["slots", "units", "pipelines"])]
    pub device: Option<crate::fpga::device::Device>,
    /// The hard multiplier products are cut for: 18x18 (ECP5 MULT18X18D) or 25x18 (the Xilinx
    /// DSP48E/DSP48E1) [default: the --device's (board's, synth --family's), else 18x18].
    #[arg(long, value_enum)]
    pub dsp: Option<DspArg>,
}

/// `--dsp`: the multiplier a product's pieces are cut for (`cores::mul::Piece`).
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum DspArg {
    #[value(name = "18x18")]
    Mult18,
    #[value(name = "25x18")]
    Dsp48,
}

impl From<DspArg> for crate::cores::mul::Piece {
    fn from(d: DspArg) -> Self {
        match d {
            DspArg::Mult18 => crate::cores::mul::Piece::Mult18,
            DspArg::Dsp48 => crate::cores::mul::Piece::Dsp48,
        }
    }
}

impl ThreadArgs {
    /// No shape option: what clap fills in (an explicit default cannot be told apart).
    pub const DEFAULT: ThreadArgs = ThreadArgs {
        slots: crate::cores::top::DEFAULT_SLOTS,
        units: crate::cores::top::DEFAULT_UNITS,
        pipelines: 1,
        device: None,
        dsp: None,
    };

    /// The hard multiplier the core's products are cut for: `--dsp`'s, else the device's, else
    /// `otherwise` (the board's or the synthesis family's, or the ECP5's).
    pub fn piece_or(&self, otherwise: crate::cores::mul::Piece) -> crate::cores::mul::Piece {
        self.dsp.map(Into::into).or(self.device.map(|d| d.piece())).unwrap_or(otherwise)
    }

    /// Whether the shape options are clap's defaults (`--dsp` is not a shape).
    pub fn shape_is_default(&self) -> bool {
        ThreadArgs { dsp: None, ..*self } == ThreadArgs::DEFAULT
    }
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

impl HwArgs {
    /// The hard multiplier the cores' products are cut for (`ThreadArgs::piece_or`).
    pub fn piece(&self) -> crate::cores::mul::Piece {
        self.threads.piece_or(Default::default())
    }
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
    /// Largest number of triangles in a BIH leaf [default: 4; with --device the fit tries 3,
    /// 4 and 5 unless given].
    #[arg(long = "leaf-size")]
    pub leaf_size: Option<u32>,
    /// Hardware traversal stack entries; bounds the BIH depth [default: 32; with --device the
    /// fit tries 32 and 16 unless given].
    #[arg(long = "stack-depth")]
    pub stack_depth: Option<u32>,
    /// The BIH's split planes: middle (the thesis's: halve the box) or sah (binned
    /// surface-area heuristic).
    #[arg(long, default_value = "sah")]
    pub tree: TreeSplit,
    /// With --tree sah: the price of a node step in hundredths of a triangle test (0..=10000);
    /// a node within --leaf-size is split further while the SAH prices the split below the
    /// leaf. 0: nodes within --leaf-size are leaves [default: 0; with --device the fit tries 0
    /// and 175 unless given].
    #[arg(long = "sah-step-percent")]
    pub sah_step_percent: Option<u32>,
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
    pub memory: MemoryArgs,
    #[command(flatten)]
    pub params: ParamArgs,
}

/// The shape of the scene image for external memory (docs/MEMORY.md).
#[derive(Args, Debug, Clone)]
pub struct MemoryArgs {
    /// Data width of the memory's AXI4 read port, bits: 32, 64 or 128.
    #[arg(long, default_value_t = crate::scene::memory::DEFAULT_MEM_BITS)]
    pub mem_bits: u32,
    /// Cache line in bytes, one AXI4 burst: a power of two, two beats to 4096.
    #[arg(long, default_value_t = crate::scene::memory::DEFAULT_LINE_BYTES)]
    pub cache_line: u32,
}

impl MemoryArgs {
    pub fn shape(&self) -> crate::error::Result<crate::scene::memory::MemoryShape> {
        let shape = crate::scene::memory::MemoryShape { mem_bits: self.mem_bits, line_bytes: self.cache_line };
        shape.validate().map_err(|(p, m)| crate::error::Error::param(p, m))?;
        Ok(shape)
    }
}

/// Where the core keeps its scene (`--memory`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MemoryPlace {
    /// In on-chip ROMs.
    Onchip,
    /// In external memory behind an AXI4 read port and on-chip caches.
    External,
    /// On chip when the ROMs fit --bram-kbits, else external.
    Auto,
}

/// The order rays are fed in (`--ray-order`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RayOrder {
    Pixels,
    /// 8 × 8-pixel tiles (the caches' friend).
    Tiles,
}

/// Where a core keeps its scene and, external, its caches (docs/MEMORY.md).
#[derive(Args, Debug, Clone)]
pub struct CoreMemoryArgs {
    /// Where the scene lives: onchip, external or auto (on chip when it fits --bram-kbits).
    #[arg(long, value_enum, default_value = "auto")]
    pub memory: MemoryPlace,
    #[command(flatten)]
    pub shape: MemoryArgs,
    /// Each traversal unit's node cache, KB.
    #[arg(long = "node-cache-kb", default_value_t = crate::cores::memory_params::DEFAULT_NODE_CACHE_KB)]
    pub node_cache_kb: u32,
    /// The triangle cache, KB.
    #[arg(long = "tri-cache-kb", default_value_t = crate::cores::memory_params::DEFAULT_TRI_CACHE_KB)]
    pub tri_cache_kb: u32,
    /// Ways of each cache: 1, 2 or 4.
    #[arg(long = "cache-ways", default_value_t = crate::cores::memory_params::DEFAULT_WAYS)]
    pub cache_ways: u32,
}

impl CoreMemoryArgs {
    pub fn spec(&self) -> crate::error::Result<crate::cores::memory_params::MemorySpec> {
        Ok(crate::cores::memory_params::MemorySpec {
            shape: self.shape.shape()?,
            node_cache_kb: self.node_cache_kb,
            tri_cache_kb: self.tri_cache_kb,
            ways: self.cache_ways,
            ..Default::default()
        })
    }
}

/// An external-memory core's options and its memory model's (docs/MEMORY.md).
#[derive(Args, Debug, Clone)]
pub struct ExternalArgs {
    #[command(flatten)]
    pub core: CoreMemoryArgs,
    /// The memory model: clocks from an address to its first beat.
    #[arg(long = "mem-latency", default_value_t = crate::verify::memory::DEFAULT_LATENCY)]
    pub mem_latency: u32,
    /// The memory model: bursts taken and not finished, at most.
    #[arg(long = "mem-outstanding", default_value_t = crate::verify::memory::DEFAULT_OUTSTANDING)]
    pub mem_outstanding: u32,
    /// The memory model: a burst's first beat up to this many clocks later still (random).
    #[arg(long = "mem-jitter", default_value_t = 0)]
    pub mem_jitter: u32,
    /// The memory model: chance in 256 that a clock carries no beat (R pauses).
    #[arg(long = "mem-pauses", default_value_t = 0)]
    pub mem_pauses: u32,
    /// The memory model's random seed (jitter and pauses).
    #[arg(long = "mem-seed", default_value_t = 1)]
    pub mem_seed: u32,
    /// Feed rays in pixel order or in 8 × 8 tiles (not with --shuffle-seed).
    #[arg(long = "ray-order", value_enum, default_value = "pixels")]
    pub ray_order: RayOrder,
}

impl ExternalArgs {
    /// The external-memory core's options and the memory model's timing, checked.
    pub fn spec(
        &self,
    ) -> crate::error::Result<(crate::cores::memory_params::MemorySpec, crate::verify::memory::MemoryTiming)> {
        let spec = self.core.spec()?;
        let timing = crate::verify::memory::MemoryTiming {
            latency: self.mem_latency,
            outstanding: self.mem_outstanding,
            extra_delay: self.mem_jitter,
            pause_in_256: self.mem_pauses,
            seed: self.mem_seed,
        };
        timing.validate().map_err(|(p, m)| crate::error::Error::param(p, m))?;
        Ok((spec, timing))
    }
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

pub(super) fn parse_vec3(s: &str) -> std::result::Result<[f64; 3], String> {
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
pub(super) fn parse_percent(s: &str) -> std::result::Result<u32, String> {
    let max = crate::verify::feed::Stalls::MAX_PERCENT;
    let p: u32 = s.trim().parse().map_err(|_| format!("'{s}' is not an integer 0..={max}"))?;
    if p > max {
        return Err(format!("{p} is out of range: must be 0..={max} (at 100 no ray is ever offered)"));
    }
    Ok(p)
}

pub(super) fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("'{s}' is not WxH"))?;
    let w: u32 = w.parse().map_err(|_| format!("'{w}' is not a positive integer"))?;
    let h: u32 = h.parse().map_err(|_| format!("'{h}' is not a positive integer"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("{w}x{h} is out of range: each side must be 1..=16384"));
    }
    Ok((w, h))
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FrameSim {
    Rust,
    Ghdl,
    Verilator,
}
