//! Drawing one random case of the differential campaign: a scene, a parameter set from the
//! whole valid range, a core shape, a camera outside or inside the scene box, and a feed
//! (shuffled, stalling). Every draw is a function of the case seed alone.

use crate::cores::memory_params::MemorySpec;
use crate::model::camera::Camera;
use crate::params::{EdgeShift, Params, TreeSplit};
use crate::rng::SplitMix64;
use crate::scene::memory::MemoryShape;
use crate::scene::{Scene, max_edge_shift};
use crate::verify::memory::MemoryTiming;

/// Where a case's triangles come from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CaseScene {
    Builtin(String),
    /// An OBJ file (the campaign's `--scenes` folder).
    File(std::path::PathBuf),
    /// `soups::scene(kind, seed)`.
    Random {
        kind: &'static str,
        seed: u64,
    },
}

impl CaseScene {
    pub fn label(&self) -> String {
        match self {
            CaseScene::Builtin(name) => name.clone(),
            CaseScene::File(path) => {
                path.file_name().map_or_else(|| path.display().to_string(), |f| f.to_string_lossy().into())
            }
            CaseScene::Random { kind, seed } => format!("{kind}#{seed:016x}"),
        }
    }
}

/// The core's shape and clock target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    pub slots: u32,
    pub units: u32,
    /// Intersection pipelines: 1, 2 or 4, dividing `units`.
    pub pipelines: u32,
    pub target_mhz: u32,
    pub div_bits: u32,
    /// The multiplier the products are cut for (`--dsp`).
    pub piece: crate::cores::mul::Piece,
}

/// One case: everything `fxrt sim` needs to run it again.
#[derive(Clone, Debug)]
pub struct Case {
    pub index: u64,
    pub scene: CaseScene,
    pub params: Params,
    pub shape: Shape,
    /// Set once the scene is built (`camera`): it depends on the scene's bounds.
    pub camera: Option<Camera>,
    pub inside: bool,
    /// Seeds the camera's draw (`camera`).
    pub camera_seed: u64,
    pub shuffle_seed: Option<u64>,
    /// (percent, seed) of the source's stalls.
    pub stalls: Option<(u32, u64)>,
    /// The scene in external memory behind caches, and the memory model's timing; None: on chip.
    pub memory: Option<(MemorySpec, MemoryTiming)>,
}

/// Built-in scenes the campaign draws (teapot-fine's core takes a minute to simulate: it is
/// left to `--scenes` runs that want a large scene).
pub const BUILTINS: [&str; 5] = ["teapot", "cornell", "jackstraws", "thin", "random"];

/// Draws case `index` of the campaign seeded `seed`; `files` are the OBJ scenes to draw from.
pub fn case(seed: u64, index: u64, files: &[std::path::PathBuf]) -> Case {
    let mut rng = SplitMix64(seed ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03));
    rng.next_u64();
    let pick = rng.below(10);
    let scene = if pick < 5 || (pick < 7 && files.is_empty()) {
        let kinds = super::soups::KINDS;
        CaseScene::Random { kind: kinds[rng.below(kinds.len() as u64) as usize], seed: rng.next_u64() }
    } else if pick < 7 {
        CaseScene::File(files[rng.below(files.len() as u64) as usize].clone())
    } else {
        CaseScene::Builtin(BUILTINS[rng.below(BUILTINS.len() as u64) as usize].into())
    };
    let params = params(&mut rng);
    let mut shape = shape(&mut rng);
    let inside = rng.below(2) == 0;
    let camera_seed = rng.next_u64();
    let shuffle_seed = (rng.below(2) == 0).then(|| rng.below(1000));
    let stalls = (rng.below(3) == 0).then(|| (1 + rng.below(60) as u32, rng.below(1000)));
    // Drawn last, so the cases of a seed keep every draw they had before external memory.
    let memory = (rng.below(3) == 0).then(|| memory(&mut rng));
    // Then the pipelines (one with the scene in external memory): each that divides the units
    // as likely.
    if memory.is_none() {
        let fits: Vec<u32> = [1, 2, 4].into_iter().filter(|p| shape.units % p == 0).collect();
        shape.pipelines = fits[rng.below(fits.len() as u64) as usize];
    }
    // Drawn after all the rest, so a case keeps its earlier draws: one in eight has 5 to 8
    // units (DECISIONS 129), its slots cut to what its closest-hit units number, its
    // pipelines drawn again among those that give each a power of two units.
    if rng.below(8) == 0 {
        shape.units = 5 + rng.below(4) as u32;
        let lanes: Vec<u32> = [1, 2, 4]
            .into_iter()
            .filter(|&p| memory.is_none() || p == 1)
            .filter(|&p| p == 1 || (shape.units % p == 0 && (shape.units / p).is_power_of_two()))
            .collect();
        shape.pipelines = lanes[rng.below(lanes.len() as u64) as usize];
        let per_lane = (shape.units / shape.pipelines).next_power_of_two();
        shape.slots = shape.slots.min(128 / per_lane);
    }
    // Last of all: one case in four cuts its products for the Xilinx DSP48E (DECISIONS 131).
    if rng.below(4) == 0 {
        shape.piece = crate::cores::mul::Piece::Dsp48;
    }
    Case { index, scene, params, shape, camera: None, inside, camera_seed, shuffle_seed, stalls, memory }
}

/// An external-memory core and a memory: small caches (a case's scene is small, and misses,
/// evictions and merged misses are what is hunted), any port width, line, associativity, and
/// a memory from fast to slow, steady to jittery and pausing. Shapes the caches cannot take
/// (a record wider than a line) are refused by `CoreParams::external` and counted.
fn memory(rng: &mut SplitMix64) -> (MemorySpec, MemoryTiming) {
    let pick = |rng: &mut SplitMix64, from: &[u32]| from[rng.below(from.len() as u64) as usize];
    let spec = MemorySpec {
        shape: MemoryShape { mem_bits: pick(rng, &[32, 64, 128]), line_bytes: pick(rng, &[32, 64, 128, 256]) },
        node_cache_kb: pick(rng, &[1, 1, 2, 4, 32]),
        tri_cache_kb: pick(rng, &[1, 1, 2, 4, 64]),
        ways: pick(rng, &[1, 2, 4]),
        ..MemorySpec::default()
    };
    let timing = MemoryTiming {
        latency: 1 + rng.below(200) as u32,
        outstanding: pick(rng, &[1, 2, 4, 16]),
        extra_delay: pick(rng, &[0, 0, 5, 30]),
        pause_in_256: pick(rng, &[0, 0, 30, 100]),
        seed: 1 + rng.below(1000) as u32,
    };
    (spec, timing)
}

/// A parameter set from the whole valid range: n and m first (every n from 4 to 40 as likely),
/// then T, C and E within the limits they imply; leaf size and stack depth mostly small, where
/// leaves and depth-limited trees change most; with the SAH, half the sets price node steps
/// (`sah_step_percent`). Sets the RTL layer cannot hold are redrawn by
/// the caller (`Params::validate` and `CoreParams::check` say which).
fn params(rng: &mut SplitMix64) -> Params {
    let n = 4 + rng.below(37) as u32;
    let m_max = 64.min(126 - 2 * n);
    let m = 8 + rng.below((m_max - 8 + 1) as u64) as u32;
    let t = if rng.below(2) == 0 { 0 } else { rng.below((m - 1) as u64) as u32 };
    let c_max = 64.min(125 - n - m);
    let c = rng.below(c_max as u64 + 1) as u32;
    let leaf_size = [1, 2, 3, 4, 4, 6, 8, 16, 64][rng.below(9) as usize];
    let stack_depth = [32, 32, 32, 4, 8, 12, 64][rng.below(7) as usize];
    let tree = if rng.below(2) == 0 { TreeSplit::Sah } else { TreeSplit::Middle };
    let mut p = Params { n, m, t, c, leaf_size, stack_depth, tree, edge_shift: EdgeShift::Auto, sah_step_percent: 0 };
    if rng.below(2) == 0 {
        p.edge_shift = EdgeShift::Fixed(rng.below(max_edge_shift(&p) as u64 + 1) as u32);
    }
    // Drawn last, so the draws before it are what they were before the option (DECISIONS 139).
    if tree == TreeSplit::Sah && rng.below(2) == 0 {
        p.sah_step_percent = [50, 100, 175, 300][rng.below(4) as usize];
    }
    p
}

/// A core shape: 1 to 64 slots (1, 2 and powers of two more often), 1 to 4 units, a clock
/// target from 50 to 400 MHz (it moves registers and so every latency), 1 or 2 quotient bits
/// per divider stage.
fn shape(rng: &mut SplitMix64) -> Shape {
    let units = 1 + rng.below(4) as u32;
    // Mostly shapes the closest-hit unit can number (at most 128 slot numbers); one in ten
    // from the whole range, to see the others refused.
    let most = if rng.below(10) == 0 { 64 } else { (128 / units.next_power_of_two()).min(64) };
    let slots = match rng.below(4) {
        0 => [1, 2, 4, 8, 16, 32, 64][rng.below(7) as usize].min(most),
        _ => 1 + rng.below(most as u64) as u32,
    };
    let target_mhz = [50, 75, 100, 125, 126, 150, 175, 200, 250, 300, 400][rng.below(11) as usize];
    Shape { slots, units, pipelines: 1, target_mhz, div_bits: 1 + rng.below(2) as u32, piece: Default::default() }
}

/// The case's camera for its built scene: inside the scene's world box (a random eye and view
/// direction), or outside it (the framing view from a random direction and distance). 6 to 24
/// pixels a side.
pub fn camera(case: &Case, scene: &Scene) -> Camera {
    let mut rng = SplitMix64(case.camera_seed);
    let (lo, hi) = crate::model::camera::world_bounds(scene);
    let (width, height) = (6 + rng.below(19) as u32, 6 + rng.below(19) as u32);
    let centre: [f64; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let radius = 0.5 * (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let unit = |rng: &mut SplitMix64| loop {
        let v: [f64; 3] = std::array::from_fn(|_| rng.range(-1.0, 1.0));
        let len = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if len > 0.1 && len <= 1.0 && v[0].abs().max(v[2].abs()) > 0.05 * len {
            break v.map(|x| x / len);
        }
    };
    let (eye, at) = if case.inside {
        let eye: [f64; 3] = std::array::from_fn(|k| rng.range(lo[k], hi[k]));
        let d = unit(&mut rng);
        (eye, std::array::from_fn(|k| eye[k] + d[k] * radius.max(1e-300)))
    } else {
        let d = unit(&mut rng);
        let dist = radius * rng.range(1.2, 4.0);
        let at: [f64; 3] = std::array::from_fn(|k| centre[k] + rng.range(-0.2, 0.2) * (hi[k] - lo[k]));
        (std::array::from_fn(|k| centre[k] + d[k] * dist), at)
    };
    let fov_deg = [20.0, 45.0, 60.0, 90.0, 120.0][rng.below(5) as usize];
    Camera { eye, at, up: [0.0, 1.0, 0.0], fov_deg, width, height }
}
