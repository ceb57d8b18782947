//! One configuration: the golden model's frame against the f64 reference, the triangle counts,
//! and the hardware cost (estimated, or from yosys with `--synth`).

use super::memory::{self, MemoryPoint, MemoryRun, MemorySweep};
use super::pnr::{PlacedModule, Pnr};
use super::{CameraSpec, Config, CoreShape, SceneSpec, Set, SweepSpec, params_label};
use crate::cores::clock::DEFAULT_TARGET_MHZ;
use crate::cores::cost::{CoreCost, core_cost, dsp48e_estimate};
use crate::cores::top::{CoreParams, DEFAULT_SLOTS, DEFAULT_UNITS, core_module_with};
use crate::error::{Error, Result};
use crate::fpga::xilinx::synth_xc5v;
use crate::model::camera::Camera;
use crate::params::Params;
use crate::render::tracer::{ModelKind, make_tracer};
use crate::render::{Frame, encode_png, render};
use crate::scene::images::SceneRoms;
use crate::scene::memory::SceneImage;
use crate::scene::{Scene, Tri, TriangleCounts, builtin, obj};
use crate::verify::feed::{Stalls, tile_order};
use crate::verify::frame::{frame_rays, mismatches, simulate_rust};
use crate::verify::frame_memory::{Stopped, simulate_external};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::sync::OnceLock;

/// Both models hit, different triangles, and the distances differ by more than this fraction:
/// a different surface, not a neighbour sharing the edge the ray passes through.
pub const OTHER_SURFACE_REL: f64 = 1e-3;

/// Bump when a row's meaning changes: old cache entries then no longer match. 2: rows of
/// `--core-sim` carry rays per clock, triangle tests and node steps per ray and the slot
/// occupancy, and rows their core's shape.
pub const ROW_FORMAT: u32 = 2;

/// The format of rows without `--core-sim`, whose keys it enters: they are what they were in
/// format 1 (the shape is absent at the default), so their keys and caches stay.
pub const PLAIN_ROW_FORMAT: u32 = 1;

/// A scene loaded once for the whole sweep, with the frames every configuration is compared to.
pub struct SceneCtx {
    pub label: String,
    /// Identifies the scene's content: a hash of the OBJ file, or the built-in's name.
    pub fingerprint: String,
    pub world: Vec<Tri>,
    pub camera: Camera,
    /// The scene at the default parameters (with the sweep's stack depth and tree), one per
    /// leaf size of the sweep, the base leaf size first.
    leaves: Vec<LeafCtx>,
}

/// The scene at the default parameters with one leaf size, and its frames: a row is compared
/// with the frames of its own leaf size, so what it says depends on its key alone.
struct LeafCtx {
    defaults: Scene,
    reference: OnceLock<Frame>,
    default_ids: OnceLock<Vec<i32>>,
}

impl SceneCtx {
    /// Loads and checks the scene, built at `defaults` and at each other of `leaf_sizes`;
    /// errors name the file and the problem.
    pub fn load(
        spec: &SceneSpec,
        label: String,
        cam: &CameraSpec,
        defaults: &Params,
        leaf_sizes: &[u32],
    ) -> Result<SceneCtx> {
        let (name, world, fingerprint) = match spec {
            SceneSpec::Builtin(b) => {
                let world = builtin::load(b)?;
                (b.clone(), world, format!("builtin:{b}"))
            }
            SceneSpec::Obj(p) => {
                let bytes = std::fs::read(p).map_err(|e| Error::file(p, format!("cannot read: {e}")))?;
                (p.display().to_string(), obj::load_obj(p)?, format!("obj:{:x}", Sha256::digest(&bytes)))
            }
        };
        let mut leaves = Vec::new();
        let others = leaf_sizes.iter().filter(|&&l| l != defaults.leaf_size);
        for leaf_size in std::iter::once(defaults.leaf_size).chain(others.copied()) {
            let p = Params { leaf_size, ..*defaults };
            let defaults = Scene::build(&name, world.clone(), &p)?;
            leaves.push(LeafCtx { defaults, reference: OnceLock::new(), default_ids: OnceLock::new() });
        }
        // The camera frames the scene's box, which the leaf size does not change.
        let camera = cam.camera(&leaves[0].defaults)?;
        Ok(SceneCtx { label, fingerprint, world, camera, leaves })
    }

    /// The default scene with `leaf_size` (the base leaf size's if the sweep has no such).
    fn leaf(&self, leaf_size: u32) -> &LeafCtx {
        self.leaves.iter().find(|l| l.defaults.params.leaf_size == leaf_size).unwrap_or(&self.leaves[0])
    }

    /// The f64 reference frame (independent of n, m, T, C and E) on the tree of `leaf_size`.
    pub fn reference(&self, leaf_size: u32) -> &Frame {
        let l = self.leaf(leaf_size);
        l.reference.get_or_init(|| {
            let tracer = make_tracer(&l.defaults, ModelKind::F64);
            render(&l.defaults, tracer.as_ref(), &self.camera, false, false)
        })
    }

    /// The golden model's triangle ids at the default parameters with `leaf_size`.
    pub fn default_ids(&self, leaf_size: u32) -> &[i32] {
        let l = self.leaf(leaf_size);
        l.default_ids.get_or_init(|| {
            let tracer = make_tracer(&l.defaults, ModelKind::Golden);
            render(&l.defaults, tracer.as_ref(), &self.camera, false, false).ids
        })
    }

    /// The cache key of `params` with a core of `shape` on this scene: everything the row
    /// depends on. The clock target enters it when it is not the default, the core's shape
    /// when it is not the default, the ECP5 modules and seed with `--family ecp5`: keys of
    /// sweeps without them are what they always were.
    pub fn key(&self, params: &Params, shape: CoreShape, spec: &SweepSpec) -> String {
        let (synth, core_sim) = (spec.synth, spec.core_sim);
        let c = &self.camera;
        let mut text = serde_json::json!({
            "fxrt": env!("CARGO_PKG_VERSION"),
            "row_format": if core_sim { ROW_FORMAT } else { PLAIN_ROW_FORMAT },
            "scene": self.fingerprint,
            "camera": [c.eye, c.at, c.up, [c.fov_deg, c.width as f64, c.height as f64]],
            "params": params,
            "synth": synth,
            "core_sim": core_sim,
        });
        if spec.target_mhz != DEFAULT_TARGET_MHZ {
            text["target_mhz"] = spec.target_mhz.into();
        }
        if (shape.slots, shape.units) != (DEFAULT_SLOTS, DEFAULT_UNITS) {
            text["slots"] = shape.slots.into();
            text["units"] = shape.units.into();
        }
        if shape.pipelines > 1 {
            text["pipelines"] = shape.pipelines.into();
        }
        if let Some(m) = &spec.memory {
            text["memory"] = serde_json::json!({ "sweep": m, "point": shape.memory });
        }
        if let (true, Some(e)) = (synth, &spec.ecp5) {
            text["family"] = "ecp5".into();
            text["ecp5"] = serde_json::json!({ "modules": e.modules, "seed": e.seed });
        }
        let text = text.to_string();
        format!("{:x}", Sha256::digest(text.as_bytes()))[..20].to_string()
    }
}

/// How the golden model's frame differs from the f64 reference.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Quality {
    pub rays: u64,
    /// Pixels the reference hits.
    pub ref_hits: u64,
    pub hits: u64,
    pub false_misses: u64,
    pub false_hits: u64,
    /// Both hit, different triangles (neighbours sharing an edge included).
    pub other_triangle: u64,
    /// Of those, the ones whose distances differ by more than `OTHER_SURFACE_REL`.
    pub other_surface: u64,
    /// false misses + false hits + other surface: the pixels that show something wrong.
    pub wrong_pixels: u64,
    /// Pixels whose triangle differs from the golden image at the default parameters.
    pub diff_vs_default: u64,
    /// Relative error of the distance where both hit the same triangle: mean and max.
    pub t_rel_mean: f64,
    pub t_rel_max: f64,
    pub triangles: TriangleCounts,
}

/// What synthesis reported (with `--synth`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SynthArea {
    pub luts: u64,
    pub srl_luts: u64,
    pub ffs: u64,
    pub dsp48e: u64,
    pub bram18: u64,
}

/// The whole core running the frame in the Rust simulator (with `--core-sim`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CoreRun {
    pub cycles_per_ray: f64,
    /// Rays per clock: 1 / `cycles_per_ray` (`fxrt sim`'s `rays_per_clock`).
    pub rays_per_clock: f64,
    /// Triangles that entered the intersection pipelines, per cycle and pipeline (as `fxrt
    /// sim`'s `pipeline_fill`).
    pub fill: f64,
    /// Triangles that entered the intersection pipeline, per ray.
    pub triangle_tests_per_ray: f64,
    /// Node visits and culled node entries of the traversal units, per ray.
    pub node_steps_per_ray: f64,
    /// The mean fraction of the core's ray slots holding a ray.
    pub slot_occupancy: f64,
    pub max_stack_depth: u64,
    /// Rays whose result differs from the golden model's (must be 0).
    pub mismatches: u64,
}

/// One configuration's results: a row of results.csv.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    pub index: usize,
    pub key: String,
    pub scene: String,
    pub params: Params,
    /// The core's ray slots and units (absent at the default, as in rows before it was swept).
    #[serde(default, skip_serializing_if = "CoreShape::is_default")]
    pub shape: CoreShape,
    /// The edge shift used (`auto` resolved).
    pub e_used: Option<u32>,
    pub quality: Option<Quality>,
    pub cost: Option<CoreCost>,
    pub synth: Option<SynthArea>,
    pub core: Option<CoreRun>,
    /// `--memory external --core-sim`: what the memory side did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub memory: Option<MemoryRun>,
    /// `--family ecp5`: each module placed and routed, in `fpga::ecp5::MODULES` order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ecp5: Vec<PlacedModule>,
    /// With `--core-sim` and `--family ecp5`: the placed core's Fmax (or the slowest placed
    /// module's) ÷ cycles per ray.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mrays_per_s_at_fmax: Option<f64>,
    /// Why part of the row is missing.
    pub error: Option<String>,
}

impl Row {
    /// The row's parameters and core shape.
    pub fn set(&self) -> Set {
        Set { params: self.params, shape: self.shape }
    }
    /// The image files of this row, relative to the sweep folder.
    pub fn image_paths(&self) -> (String, String) {
        let base = format!("images/{}/{}", self.scene, params_label(&self.params));
        (format!("{base}.png"), format!("{base}_errors.png"))
    }
    /// The DSP48E count to rank by: yosys's when the sweep synthesises (None if it failed
    /// here), else the estimate.
    pub fn dsp48e(&self, synth: bool) -> Option<u64> {
        if synth { self.synth.as_ref().map(|s| s.dsp48e) } else { self.cost.as_ref().map(|c| c.dsp48e_est as u64) }
    }
}

/// A row and its two pictures (PNG bytes; empty when the scene could not be built).
pub struct Evaluated {
    pub row: Row,
    pub render_png: Vec<u8>,
    pub errors_png: Vec<u8>,
}

/// What to do besides the image comparison and the estimated cost.
#[derive(Clone, Debug)]
pub struct Extras {
    /// Synthesise with yosys, in DIR/KEY.
    pub synth_dir: Option<std::path::PathBuf>,
    pub core_sim: bool,
    /// The clock the cores are built for, MHz.
    pub target_mhz: u32,
    /// Place and route on the ECP5 (`--family ecp5`), in DIR/KEY/MODULE.
    pub pnr: Option<Pnr>,
    /// `--memory external`: the cores read their scene from external memory.
    pub memory: Option<MemorySweep>,
    /// `--device`: each row's core is counted against the device the shape was fitted to.
    pub device: Option<crate::fpga::device::Device>,
}

pub fn evaluate(ctx: &SceneCtx, cfg: &Config, key: String, extras: &Extras) -> Evaluated {
    let mut row = Row {
        index: cfg.index,
        key,
        scene: ctx.label.clone(),
        params: cfg.params,
        shape: cfg.shape,
        e_used: None,
        quality: None,
        cost: None,
        synth: None,
        core: None,
        memory: None,
        ecp5: Vec::new(),
        mrays_per_s_at_fmax: None,
        error: None,
    };
    let scene = match Scene::build(&ctx.label, ctx.world.clone(), &cfg.params) {
        Ok(s) => s,
        Err(e) => {
            row.error = Some(e.message);
            return Evaluated { row, render_png: vec![], errors_png: vec![] };
        }
    };
    row.e_used = Some(scene.edge_shift);
    let tracer = make_tracer(&scene, ModelKind::Golden);
    let frame = render(&scene, tracer.as_ref(), &ctx.camera, false, false);
    let reference = ctx.reference(cfg.params.leaf_size);
    let mut q = quality(&frame, reference, ctx.default_ids(cfg.params.leaf_size));
    q.triangles = scene.counts;
    row.quality = Some(q);
    let roms = SceneRoms::of(&scene);
    match core_cost(&roms) {
        Ok(c) if extras.target_mhz != DEFAULT_TARGET_MHZ || !cfg.shape.is_default() => {
            row.cost = Some(cost_at(c, &roms, extras, cfg.shape))
        }
        Ok(c) => row.cost = Some(c),
        Err(e) => row.error = Some(e.to_string()),
    }
    // The frame's pixel numbers are the ray ids (as `fxrt sim` does it).
    let id_width = crate::scene::rom::addr_bits((ctx.camera.width * ctx.camera.height) as usize).max(1);
    let CoreShape { slots, units, pipelines, .. } = cfg.shape;
    // A core fitted to a device cuts its products for the device's multipliers.
    let piece = extras.device.map(|d| d.piece()).unwrap_or_default();
    let core_spec = crate::cores::top::CoreSpec {
        id_width,
        div_bits: 1,
        target_mhz: extras.target_mhz,
        slots,
        units,
        pipelines,
        piece,
    };
    let core_params = match &extras.memory {
        None => CoreParams::shaped(&roms, &core_spec),
        Some(m) => match CoreParams::external(&roms, &core_spec, m.spec(cfg.shape.memory)) {
            Ok(p) => p,
            Err(e) => {
                row.error = Some(e.to_string());
                return Evaluated { render_png: frame.png_bytes(), errors_png: errors_png(&frame, reference), row };
            }
        },
    };
    // The shape was fitted at the base set; a set of wider arithmetic may need more.
    if let Some(why) = extras.device.and_then(|d| super::fit::lacks(d, &roms, &core_params)) {
        row.error = Some(format!("--device: {why}"));
    }
    if let (true, Some(_)) = (extras.core_sim, &row.cost) {
        match simulate_core(&scene, &ctx.camera, &core_params, &roms, cfg.shape.memory, &extras.memory) {
            Ok((run, memory)) => {
                if run.mismatches > 0 {
                    row.error = Some(format!("the core disagrees with the golden model on {} rays", run.mismatches));
                }
                row.core = Some(run);
                row.memory = memory;
            }
            Err(stopped) => row.error = Some(stopped.to_string()),
        }
    }
    if let (Some(dir), Some(_)) = (&extras.synth_dir, &row.cost) {
        let core = core_module_with(&core_params, &roms, false);
        match synth_xc5v(&core, &dir.join(&row.key)) {
            Ok(a) => {
                row.synth = Some(SynthArea {
                    luts: a.luts,
                    srl_luts: a.srl_luts,
                    ffs: a.ffs,
                    dsp48e: a.dsp48e,
                    bram18: a.bram18,
                })
            }
            Err(e) => row.error = Some(e.to_string()),
        }
    }
    if let (Some(pnr), Some(_)) = (&extras.pnr, &row.cost) {
        let (placed, error) = pnr.place(&row.key, &core_params, &roms);
        row.ecp5 = placed;
        match (error, &row.core, super::pnr::clock(&row.ecp5)) {
            (Some(e), _, _) => row.error = Some(e),
            (None, Some(run), Some(mhz)) => {
                row.mrays_per_s_at_fmax = Some((mhz / run.cycles_per_ray * 1e4).round() / 1e4)
            }
            _ => {}
        }
    }
    let render_png = frame.png_bytes();
    let errors_png = errors_png(&frame, reference);
    Evaluated { row, render_png, errors_png }
}

/// The frame through the core of `p` in the Rust simulator: the core's figures and, for an
/// external-memory core (`memory`), the memory side's at `point`'s latency; `Stopped` if that
/// core stopped producing results.
fn simulate_core(
    scene: &Scene,
    camera: &Camera,
    p: &CoreParams,
    roms: &SceneRoms,
    point: MemoryPoint,
    memory: &Option<MemorySweep>,
) -> std::result::Result<(CoreRun, Option<MemoryRun>), Stopped> {
    let rays = frame_rays(scene, camera);
    let (results, stats, ms) = match (memory, &p.mem) {
        (Some(m), Some(ext)) => {
            let rays = if m.tiles { tile_order(&rays, |r| r.pixel, camera.width, 8) } else { rays.clone() };
            // The image of a scene the core was just built for fits its own layout.
            let image = SceneImage::build(roms, ext.spec.shape).expect("the scene image of a built core");
            let (results, stats, ms) =
                simulate_external(p, roms, &image, &rays, memory::timing(point), &Stalls::none(), &|_| {})?;
            (
                results,
                stats,
                Some(MemoryRun { figures: ms.figures, cache_bram_bits: ext.bram_bits(p.units, p.total_slots()) }),
            )
        }
        _ => {
            let (results, stats) = simulate_rust(p, roms, &rays, &Stalls::none(), &|_| {});
            (results, stats, None)
        }
    };
    let run = CoreRun {
        cycles_per_ray: stats.cycles_per_ray(),
        rays_per_clock: stats.rays_per_clock(),
        fill: stats.fill() / p.pipelines as f64,
        triangle_tests_per_ray: stats.triangle_tests_per_ray(),
        node_steps_per_ray: stats.node_steps_per_ray(),
        slot_occupancy: stats.slot_occupancy(),
        max_stack_depth: stats.max_stack_depth as u64,
        mismatches: mismatches(scene, &rays, &results),
    };
    Ok((run, ms))
}

/// `cost` (`core_cost`'s, for the default core) with what the clock target and the core's
/// shape change: the divider's and the intersection pipeline's latencies, the registers and
/// the multipliers' pieces (cut for the device's multipliers under `--device`, as the row's
/// core is). The ROMs do not depend on them.
fn cost_at(cost: CoreCost, roms: &SceneRoms, extras: &Extras, shape: CoreShape) -> CoreCost {
    let p = CoreParams::shaped(
        roms,
        &crate::cores::top::CoreSpec {
            target_mhz: extras.target_mhz,
            slots: shape.slots,
            units: shape.units,
            pipelines: shape.pipelines,
            piece: extras.device.map(|d| d.piece()).unwrap_or_default(),
            ..Default::default()
        },
    );
    let core = core_module_with(&p, roms, false);
    CoreCost {
        div_latency: p.isect.div_latency(),
        isect_latency: p.isect.latency(),
        dsp48e_est: dsp48e_estimate(&core),
        register_bits: core.register_bits(),
        ..cost
    }
}

/// |golden − reference| / reference, finite even where the reference distance is 0.
fn rel_diff(golden: f64, reference: f64) -> f64 {
    let d = (golden - reference).abs();
    if reference > 0.0 {
        d / reference
    } else if d == 0.0 {
        0.0
    } else {
        1.0
    }
}

/// Pixel-by-pixel comparison with the reference and with the default-parameter image.
pub fn quality(golden: &Frame, reference: &Frame, default_ids: &[i32]) -> Quality {
    let mut q = Quality { rays: golden.ids.len() as u64, ..Default::default() };
    let (mut t_sum, mut t_count) = (0.0, 0u64);
    for i in 0..golden.ids.len() {
        let (g, r) = (golden.ids[i], reference.ids[i]);
        q.ref_hits += (r >= 0) as u64;
        q.hits += (g >= 0) as u64;
        q.diff_vs_default += (g != default_ids[i]) as u64;
        match (g >= 0, r >= 0) {
            (true, false) => q.false_hits += 1,
            (false, true) => q.false_misses += 1,
            (true, true) => {
                let rel = rel_diff(golden.depth[i], reference.depth[i]);
                if g != r {
                    q.other_triangle += 1;
                    q.other_surface += (rel > OTHER_SURFACE_REL) as u64;
                } else {
                    t_sum += rel;
                    t_count += 1;
                    q.t_rel_max = q.t_rel_max.max(rel);
                }
            }
            (false, false) => {}
        }
    }
    q.wrong_pixels = q.false_misses + q.false_hits + q.other_surface;
    q.t_rel_mean = if t_count == 0 { 0.0 } else { t_sum / t_count as f64 };
    q
}

/// The render in grey with what is wrong in colour: false hits red, false misses blue,
/// other surfaces magenta.
pub fn errors_png(golden: &Frame, reference: &Frame) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(golden.ids.len() * 3);
    for i in 0..golden.ids.len() {
        let (g, r) = (golden.ids[i], reference.ids[i]);
        let grey = if golden.shade[i] < 0.0 { 30 } else { (40.0 + 150.0 * golden.shade[i].clamp(0.0, 1.0)) as u8 };
        let px = match (g >= 0, r >= 0) {
            (true, false) => [235, 40, 40],
            (false, true) => [40, 110, 255],
            (true, true) if g != r && rel_diff(golden.depth[i], reference.depth[i]) > OTHER_SURFACE_REL => {
                [230, 40, 230]
            }
            _ => [grey; 3],
        };
        rgb.extend_from_slice(&px);
    }
    encode_png(golden.width, golden.height, &rgb)
}
