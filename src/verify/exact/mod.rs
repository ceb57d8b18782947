//! The differential campaign (`fxrt bench exact`): random cases — scenes (random interiors,
//! coplanar layers, fans, soups, the built-ins, OBJ files), parameter sets from the whole valid
//! range, core shapes, cameras outside and inside the scene box, shuffled and stalling feeds —
//! each run through the whole generated core in the Rust simulator, every ray's result compared
//! with the golden model's culled walk (`Golden::trace_culled`), and the core's node steps and
//! triangle tests with that walk's. A case also checks the model against itself: the full walk
//! (`Golden::trace`) and the renderer's fast form must give the same hit.
//!
//! The first case that disagrees is written out as a self-contained reproducer (`repro`): the
//! scene as OBJ, the case as JSON, and the `fxrt sim` command that runs it again.

pub mod draw;
pub mod repro;
pub mod soups;

use crate::cores::top::CoreParams;
use crate::model::golden::{Golden, GridRay, Hit};
use crate::render::fast::FastGolden;
use crate::scene::images::SceneRoms;
use crate::scene::memory::SceneImage;
use crate::scene::{Scene, Tri};
use crate::verify::feed::{Stalls, feed_order};
use crate::verify::frame::{PixelRay, frame_rays, frame_stream, run_stream, simulate_hdl, simulate_rust};
use crate::verify::frame_memory::simulate_external;
use crate::verify::simulators::Simulator;
use draw::{Case, CaseScene};
use serde::Serialize;
use std::collections::BTreeSet;
use std::path::PathBuf;

/// A ray whose result differs: what the core gave (None: no result came), the culled walk's
/// and the full walk's hit (the model's own disagreement when those two differ).
#[derive(Clone, Debug, Serialize)]
pub struct RayDisagreement {
    pub pixel: u32,
    pub ray: GridRay,
    pub core: Option<Option<Hit>>,
    pub golden: Option<Hit>,
    pub golden_full: Option<Hit>,
    pub golden_fast: Option<Hit>,
}

/// What one case found.
#[derive(Clone, Debug)]
pub struct CaseOutcome {
    pub rays: u64,
    pub cycles: u64,
    /// Rays whose results differ (core, or the model with itself), at most 16 kept.
    pub disagreements: Vec<RayDisagreement>,
    pub disagreeing_rays: u64,
    /// Results the core gave for no ray, or twice.
    pub stray_results: u64,
    /// The core's node steps (visits and culled entries) and triangle tests, and the golden
    /// culled walk's over the same rays: equal when the hardware walks as specified.
    pub core_walk: (u64, u64),
    pub golden_walk: (u64, u64),
    /// The HDL simulator the frame also ran in (`Campaign::hdl`), and what differed there from
    /// the Rust simulator's run — results, their order, cycles, triangle tests — or why it
    /// failed; None when it was not run or agreed.
    pub hdl: Option<Simulator>,
    pub hdl_disagreement: Option<String>,
}

impl CaseOutcome {
    pub fn agrees(&self) -> bool {
        self.disagreeing_rays == 0
            && self.stray_results == 0
            && self.core_walk == self.golden_walk
            && self.hdl_disagreement.is_none()
    }
}

/// A case's built inputs: the scene, its ROMs, the core's parameters and the rays in feed
/// order.
pub struct Built {
    pub scene: Scene,
    pub roms: SceneRoms,
    pub core: CoreParams,
    pub rays: Vec<PixelRay>,
    /// The scene's image in memory, for a core with its scene there.
    pub image: Option<SceneImage>,
}

/// The triangles of a case's scene.
pub fn triangles(scene: &CaseScene) -> crate::error::Result<Vec<Tri>> {
    match scene {
        CaseScene::Builtin(name) => crate::scene::builtin::load(name),
        CaseScene::File(path) => crate::scene::obj::load_obj(path),
        CaseScene::Random { kind, seed } => Ok(soups::scene(kind, *seed)),
    }
}

/// Builds a case (and fills in its camera). Err: the case is refused as `fxrt sim` would
/// refuse it (a scene the parameters cannot grid, a shape the RTL layer cannot hold), with
/// the message it would print.
pub fn build(case: &mut Case, tris: Vec<Tri>) -> crate::error::Result<Built> {
    case.params.validate()?;
    let scene = Scene::build(&case.scene.label(), tris, &case.params)?;
    let mut cam = draw::camera(case, &scene);
    cam.validate().map_err(|(opt, msg)| crate::error::Error::param(opt, msg))?;
    // A frame whose walks would take the core more than `MAX_CYCLES` (a one-slot core on a
    // deep scene) is made smaller, so every case takes seconds, not minutes.
    let mut rays = frame_rays(&scene, &cam);
    // An external-memory core waits on its memory and simulates at a third of the speed.
    let budget = if case.memory.is_some() { MAX_CYCLES / 4 } else { MAX_CYCLES };
    while cam.width * cam.height > 4 && estimated_cycles(&scene, &rays, case.shape) > budget {
        (cam.width, cam.height) = ((cam.width * 7 / 10).max(2), (cam.height * 7 / 10).max(2));
        rays = frame_rays(&scene, &cam);
    }
    case.camera = Some(cam);
    let roms = SceneRoms::of(&scene);
    let id_width = crate::scene::rom::addr_bits((cam.width * cam.height) as usize);
    let s = case.shape;
    let spec = crate::cores::top::CoreSpec {
        id_width,
        div_bits: s.div_bits,
        target_mhz: s.target_mhz,
        slots: s.slots,
        units: s.units,
        pipelines: s.pipelines,
        piece: s.piece,
    };
    let core = CoreParams::shaped(&roms, &spec);
    core.check()?;
    let (core, image) = match case.memory {
        Some((mem, _)) => (CoreParams::external(&roms, &spec, mem)?, Some(SceneImage::build(&roms, mem.shape)?)),
        None => (core, None),
    };
    let rays = feed_order(&rays, case.shuffle_seed);
    Ok(Built { scene, roms, core, rays, image })
}

/// About what a case may cost: the Rust simulator runs the core at some 6,000 cycles a second.
const MAX_CYCLES: u64 = 30_000;

/// A rough count of the core's cycles for `rays`: a unit steps a node per clock with enough
/// slots (the ring is some 25 clocks long), a slot waits some 80 clocks per leaf, and the
/// pipeline takes a triangle per clock.
fn estimated_cycles(scene: &Scene, rays: &[PixelRay], shape: draw::Shape) -> u64 {
    let (steps, tests) = crate::verify::frame::golden_walk(scene, rays);
    let parallel = (shape.slots * shape.units).min(25) as u64;
    steps * 25 / parallel + tests * 20 / parallel + tests
}

/// Runs a built case through the core in the Rust simulator and compares every ray; with
/// `hdl`, the same frame in that simulator too, which must give the same results in the same
/// order, in the same cycles (its testbench checks every result against the golden model).
pub fn run(case: &Case, b: &Built, hdl: Option<Simulator>) -> CaseOutcome {
    let stalls = case.stalls.map_or_else(Stalls::none, |(percent, seed)| Stalls::random(percent, seed));
    let external = b.image.as_ref().zip(case.memory.map(|m| m.1));
    let (results, stats) = match external {
        Some((image, timing)) => {
            // A core that stops is a finding, recorded as a panic is (`run_case`).
            let run = simulate_external(&b.core, &b.roms, image, &b.rays, timing, &stalls, &|_| {});
            let (results, stats, _) = run.unwrap_or_else(|stopped| panic!("{stopped}"));
            (results, stats)
        }
        None => simulate_rust(&b.core, &b.roms, &b.rays, &stalls, &|_| {}),
    };
    let mut out = compare(&b.scene, &b.rays, &results, (stats.visits + stats.culls, stats.busy_cycles), stats.cycles);
    if let Some(sim) = hdl {
        out.hdl = Some(sim);
        let dir = tempfile::tempdir().expect("a temporary folder");
        let ran = match external {
            // The testbench's memory model with the case's timing (frame_stream gives it the image).
            Some((_, timing)) => frame_stream(&b.core, &b.scene, &b.rays, &stalls).and_then(|mut stream| {
                if let Some((t, _)) = stream.memory.as_mut() {
                    *t = timing;
                }
                run_stream(sim, &stream, dir.path())
            }),
            None => simulate_hdl(sim, &b.core, &b.scene, &b.rays, &stalls, dir.path()),
        };
        out.hdl_disagreement = match ran {
            Err(e) => Some(e.to_string()),
            Ok((r, _)) if r != results => Some(format!("{} results differ from the Rust simulator's", sim.name())),
            Ok((_, st)) if (st.cycles, st.busy_cycles) != (stats.cycles, stats.busy_cycles) => Some(format!(
                "{}: {} cycles and {} triangle tests, the Rust simulator {} and {}",
                sim.name(),
                st.cycles,
                st.busy_cycles,
                stats.cycles,
                stats.busy_cycles
            )),
            Ok(_) => None,
        };
    }
    out
}

/// Every ray's result against the golden model; the core's walk totals against the culled
/// walk's.
pub fn compare(
    scene: &Scene,
    rays: &[PixelRay],
    results: &[crate::verify::frame::CoreResult],
    core_walk: (u64, u64),
    cycles: u64,
) -> CaseOutcome {
    let g = Golden::new(scene);
    let fast = FastGolden::new(scene);
    let mut got: Vec<Option<Option<Hit>>> = vec![None; rays.len()];
    let by_pixel: std::collections::BTreeMap<u64, usize> =
        rays.iter().enumerate().map(|(k, r)| (r.pixel as u64, k)).collect();
    let mut stray = 0;
    for (id, hit) in results {
        match by_pixel.get(id) {
            Some(&k) if got[k].is_none() => got[k] = Some(*hit),
            _ => stray += 1,
        }
    }
    let mut out = CaseOutcome {
        rays: rays.len() as u64,
        cycles,
        disagreements: Vec::new(),
        disagreeing_rays: 0,
        stray_results: stray,
        core_walk,
        golden_walk: (0, 0),
        hdl: None,
        hdl_disagreement: None,
    };
    for (k, r) in rays.iter().enumerate() {
        let (golden, st) = g.trace_culled(scene, &r.ray);
        out.golden_walk.0 += (st.nodes + st.culled) as u64;
        out.golden_walk.1 += st.tri_tests as u64;
        let golden_full = g.trace(scene, &r.ray).0;
        let golden_fast = fast.trace(&r.ray).0;
        if got[k] != Some(golden) || golden_full != golden || golden_fast != golden {
            out.disagreeing_rays += 1;
            if out.disagreements.len() < 16 {
                out.disagreements.push(RayDisagreement {
                    pixel: r.pixel,
                    ray: r.ray,
                    core: got[k],
                    golden,
                    golden_full,
                    golden_fast,
                });
            }
        }
    }
    out
}

/// How one case ended.
#[derive(Clone, Debug)]
pub enum Verdict {
    /// `fxrt sim` refuses the case (exit 2 with this message): not a finding.
    Refused(crate::error::Error),
    Ran(CaseOutcome),
    /// Building or simulating the case panicked: an accepted parameter set that does not work.
    Panicked(String),
}

/// A case as it ran: its triangles (for the reproducer) and how it ended.
pub struct CaseRun {
    pub case: Case,
    pub tris: Option<Vec<Tri>>,
    pub verdict: Verdict,
}

impl CaseRun {
    pub fn is_finding(&self) -> bool {
        match &self.verdict {
            Verdict::Ran(o) => !o.agrees(),
            Verdict::Panicked(_) => true,
            Verdict::Refused(_) => false,
        }
    }
}

/// Draws, builds and runs case `index` (with `hdl`, in that simulator too), catching a panic
/// as a finding.
pub fn run_case(seed: u64, index: u64, files: &[PathBuf], hdl: Option<Simulator>) -> CaseRun {
    let mut case = draw::case(seed, index, files);
    let tris = match triangles(&case.scene) {
        Ok(t) => t,
        Err(e) => return CaseRun { case, tris: None, verdict: Verdict::Refused(e) },
    };
    let attempt = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        build(&mut case, tris.clone()).map(|b| run(&case, &b, hdl))
    }));
    let verdict = match attempt {
        Ok(Ok(outcome)) => Verdict::Ran(outcome),
        Ok(Err(e)) => Verdict::Refused(e),
        Err(payload) => Verdict::Panicked(
            payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "a panic without a message".into()),
        ),
    };
    // The camera is drawn inside `build`; a panic before it leaves the case without one.
    CaseRun { case, tris: Some(tris), verdict }
}

/// How a campaign runs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Campaign {
    pub seed: u64,
    /// Stop drawing new cases after this long.
    pub budget: std::time::Duration,
    /// Or after this many cases (whichever comes first).
    pub max_cases: Option<u64>,
    /// OBJ scenes to draw from besides the random and built-in ones.
    pub files: Vec<PathBuf>,
    /// Where the first disagreement's reproducer goes.
    pub out: PathBuf,
    /// Every `hdl.1`-th case (0, k, 2k, …) also runs in HDL simulator `hdl.0`.
    pub hdl: Option<(Simulator, u64)>,
}

/// What a campaign did.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Report {
    pub seed: u64,
    pub seconds: f64,
    pub cases: u64,
    /// Cases `fxrt sim` would refuse (exit 2), by the option it names.
    pub refused: u64,
    pub refused_by: std::collections::BTreeMap<String, u64>,
    pub rays: u64,
    pub cycles: u64,
    pub scenes: usize,
    pub parameter_sets: usize,
    pub shapes: usize,
    pub inside_cameras: u64,
    /// Cases that ran with the scene in external memory (tiny caches, a random memory).
    pub external_cases: u64,
    /// Cases run with the products cut for the DSP48E (`--dsp 25x18`).
    pub dsp48_cases: u64,
    /// Cases that also ran in the HDL simulator.
    pub hdl_cases: u64,
    /// Cases with a wrong result, walk or panic, and rays with a wrong result.
    pub findings: u64,
    pub disagreeing_rays: u64,
    pub panics: u64,
    /// The first finding: its case index and reproducer folder.
    pub first: Option<(u64, PathBuf)>,
}

/// Runs cases `0, 1, 2, …` until the time or case budget is spent, as many at a time as the
/// thread pool has threads; `progress(cases done, rays)` after each batch. The campaign stops
/// at the first finding (the lowest case index of its batch) and writes it out with
/// `repro::write`.
pub fn campaign(c: &Campaign, progress: &dyn Fn(u64, u64)) -> crate::error::Result<Report> {
    use rayon::prelude::*;
    let start = std::time::Instant::now();
    let mut report = Report { seed: c.seed, ..Report::default() };
    let (mut scenes, mut params, mut shapes) = (BTreeSet::new(), BTreeSet::new(), BTreeSet::new());
    let batch = rayon::current_num_threads().max(1) as u64;
    let mut next = 0u64;
    let mut first: Option<CaseRun> = None;
    while start.elapsed() < c.budget && c.max_cases.is_none_or(|m| next < m) && first.is_none() {
        let count = c.max_cases.map_or(batch, |m| batch.min(m - next));
        let runs: Vec<CaseRun> = (next..next + count)
            .into_par_iter()
            .map(|i| run_case(c.seed, i, &c.files, c.hdl.filter(|h| i % h.1 == 0).map(|h| h.0)))
            .collect();
        next += count;
        for run in runs {
            report.cases += 1;
            match &run.verdict {
                Verdict::Refused(e) => {
                    report.refused += 1;
                    *report.refused_by.entry(e.subject.clone()).or_default() += 1;
                }
                Verdict::Ran(o) => {
                    report.rays += o.rays;
                    report.cycles += o.cycles;
                    report.inside_cameras += run.case.inside as u64;
                    report.external_cases += run.case.memory.is_some() as u64;
                    report.dsp48_cases += (run.case.shape.piece == crate::cores::mul::Piece::Dsp48) as u64;
                    report.hdl_cases += o.hdl.is_some() as u64;
                    report.disagreeing_rays += o.disagreeing_rays;
                    scenes.insert(run.case.scene.label());
                    params.insert(format!("{:?}", run.case.params));
                    shapes.insert(format!("{:?}", run.case.shape));
                }
                Verdict::Panicked(_) => report.panics += 1,
            }
            if run.is_finding() {
                report.findings += 1;
                if first.is_none() {
                    first = Some(run);
                }
            }
        }
        progress(report.cases, report.rays);
    }
    report.seconds = start.elapsed().as_secs_f64();
    (report.scenes, report.parameter_sets, report.shapes) = (scenes.len(), params.len(), shapes.len());
    if let Some(run) = first {
        let dir = repro::write(&c.out, &run)?;
        report.first = Some((run.case.index, dir));
    }
    Ok(report)
}
