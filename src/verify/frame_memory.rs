//! Whole frames through an external-memory core (`--memory external`) in the cycle simulator,
//! its AXI4 read port answered by the memory model (`verify::memory`) from the scene image:
//! the same rays and checks as `verify::frame`, and what the memory side did (`MemoryStats`).

use super::feed::Stalls;
use super::frame::{CoreResult, CoreStats, OBSERVED, RESULT_PORTS, core_result, port};
use super::memory::{MasterOut, MemoryModel, MemoryTiming, SIM_BASE};
use crate::cores::top::{CoreParams, core_inputs, core_module, ray_inputs};
use crate::cores::top_memory::memory_inputs;
use crate::rtl::sim::Sim;
use crate::scene::images::SceneRoms;
use crate::scene::memory::SceneImage;
use crate::verify::frame::PixelRay;
use serde::{Deserialize, Serialize};

/// Observation ports of an external-memory core, in `MemoryStats::count` order.
pub const MEMORY_OBSERVED: [&str; 6] = ["node_looks", "node_hits", "tri_looks", "tri_hits", "mem_beat", "mem_stall"];

/// What the memory side did over a frame.
#[derive(Clone, Debug, Default, Serialize)]
pub struct MemoryStats {
    pub latency: u32,
    pub mem_bits: u32,
    /// Bursts (cache lines) read and beats carried.
    pub reads: u64,
    pub beats: u64,
    pub node_lookups: u64,
    pub node_hits: u64,
    pub tri_lookups: u64,
    pub tri_hits: u64,
    /// Clocks in which a beat came in (the R channel busy).
    pub beat_clocks: u64,
    /// Clocks in which no triangle entered the pipeline while a leaf waited for memory.
    pub stall_clocks: u64,
    /// Derived figures (`finish`): per ray, rates and fractions.
    #[serde(flatten)]
    pub figures: MemoryFigures,
}

/// What the memory side did, per ray and per clock: `fxrt sim`'s JSON and a sweep's row.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MemoryFigures {
    pub mem_bytes_per_ray: f64,
    pub mem_reads_per_ray: f64,
    pub node_cache_hit_rate: f64,
    pub tri_cache_hit_rate: f64,
    /// Fraction of clocks the R channel carried a beat.
    pub mem_busy: f64,
    /// Fraction of clocks no triangle entered the pipeline while a leaf waited for memory.
    pub memory_stall_fraction: f64,
}

impl MemoryStats {
    fn count(&mut self, row: &[i128; 6]) {
        self.node_lookups += row[0] as u64;
        self.node_hits += row[1] as u64;
        self.tri_lookups += row[2] as u64;
        self.tri_hits += row[3] as u64;
        self.beat_clocks += row[4] as u64;
        self.stall_clocks += row[5] as u64;
    }

    fn finish(&mut self, rays: u64, cycles: u64) {
        let (rays, cycles) = (rays.max(1) as f64, cycles.max(1) as f64);
        self.figures = MemoryFigures {
            mem_bytes_per_ray: (self.beats * self.mem_bits as u64 / 8) as f64 / rays,
            mem_reads_per_ray: self.reads as f64 / rays,
            node_cache_hit_rate: self.node_hits as f64 / self.node_lookups.max(1) as f64,
            tri_cache_hit_rate: self.tri_hits as f64 / self.tri_lookups.max(1) as f64,
            mem_busy: self.beat_clocks as f64 / cycles,
            memory_stall_fraction: self.stall_clocks as f64 / cycles,
        };
    }
}

/// When a run through an external-memory core has stopped making progress. A slow memory
/// may make a frame take millions of clocks (thousands of triangle tests a ray, each a miss
/// through a tiny cache), so the bound is not on the frame's clocks but on progress:
/// - (a) the clocks without a result, a node step, a triangle test or a newly staged triangle
///   record (a triangle-cache hit: only records not yet staged are looked up, DECISIONS 109);
///   a core that fetches the same lines for ever (a livelock) stages nothing;
/// - (b) the node steps and tests themselves: a ray visits each node (or culls it) and tests
///   each leaf entry at most once (doubled for margin);
/// - (c) the records staged between two node steps or tests: each slot has one leaf in flight
///   and stages each of its records once, so more than slots × the staging places per slot
///   means records are fetched again and again (a leaf that evicts its own lines, DECISIONS 103).
///
/// (a) counted only results, steps and tests until campaign seed 24's case 500: a leaf of
/// ~1,500 records, one to a line, through one outstanding read of latency 175 took 300,000
/// clocks to stage with no step in between, and the run was stopped while it progressed.
struct RunLimits {
    quiet: u64,
    walk: u64,
    /// Records the slots can stage between two node steps or tests (c).
    staged: u64,
    /// Node steps and tests seen at the last progress, and records staged by then.
    walked_before: u64,
    staged_before: u64,
    /// Records staged by the last node step or test, and the clock of the last progress.
    staged_at_walk: u64,
    last_progress: u64,
}

impl RunLimits {
    fn new(p: &CoreParams, roms: &SceneRoms, rays: u64, timing: &MemoryTiming) -> RunLimits {
        let mem = p.mem.as_ref().expect("an external-memory core");
        let shape = mem.spec.shape;
        let beats = (shape.line_bytes * 8 / shape.mem_bits) as u64;
        // Clocks one line takes at the worst: latency, extra delay, its beats through the pauses.
        let pause = timing.pause_in_256.min(255) as u64;
        let per_line = (timing.latency + timing.extra_delay) as u64 + (beats * 256).div_ceil(256 - pause) + 1;
        // A step may wait behind every fill the askers have in flight and a leaf's retries:
        // 2,000 lines is far beyond either.
        let quiet = 50_000 + 2_000 * per_line;
        let walk = 2 * rays * (roms.node.1.len() + roms.leaf.1.len()) as u64 + 1;
        let staged = p.slot_count() as u64 * (1u64 << mem.stage_bits);
        RunLimits { quiet, walk, staged, walked_before: 0, staged_before: 0, staged_at_walk: 0, last_progress: 0 }
    }

    /// Takes the counts after clock `cycle` (whether a result came out, the node steps and
    /// tests so far, the records staged so far); Err with the reason once the run has stopped
    /// making progress.
    fn check(&mut self, cycle: u64, result: bool, walked: u64, staged: u64) -> Result<(), String> {
        if result || walked > self.walked_before {
            (self.last_progress, self.walked_before, self.staged_at_walk) = (cycle, walked, staged);
        } else if staged > self.staged_before && staged - self.staged_at_walk <= self.staged {
            self.last_progress = cycle;
        }
        self.staged_before = staged;
        let since_walk = staged - self.staged_at_walk;
        if cycle - self.last_progress >= self.quiet {
            Err(format!(
                "{walked} node steps and tests and {staged} records staged, the last {} clocks ago",
                cycle - self.last_progress
            ))
        } else if walked > self.walk {
            Err(format!("{walked} node steps and tests, more than the {} the rays can take", self.walk))
        } else if since_walk > self.staged {
            Err(format!("{since_walk} records staged since the last node step or test, more than the slots hold"))
        } else {
            Ok(())
        }
    }
}

/// Why a run through an external-memory core was given up: it stopped producing results
/// (`RunLimits`), or its read master flagged a memory error. A defect of the core, not of the
/// input: `fxrt sim` prints it on one line and exits 1, the campaign records it as a finding.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Stopped(pub String);

impl std::fmt::Display for Stopped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Stopped {}

/// Streams `rays` (in the order given, the source holding back on the cycles of `stalls` as the
/// testbenches' does, every result taken when shown) through the core of `p` (which must have
/// external memory) in the cycle simulator, the memory model of `timing` answering from
/// `image` at `SIM_BASE`. Returns the results in the order they came out, the
/// core's counts and the memory side's; `Stopped` if the core stops producing results or
/// flags a memory error.
pub fn simulate_external(
    p: &CoreParams,
    roms: &SceneRoms,
    image: &SceneImage,
    rays: &[PixelRay],
    timing: MemoryTiming,
    stalls: &Stalls,
    progress: &dyn Fn(u64),
) -> Result<(Vec<CoreResult>, CoreStats, MemoryStats), Stopped> {
    let mem = p.mem.as_ref().expect("an external-memory core");
    let m = core_module(p, roms);
    let mut sim = Sim::new(&m);
    let ins: Vec<_> = core_inputs(p).iter().map(|(name, _)| port(&m, name)).collect();
    let mem_ins: Vec<_> = memory_inputs(mem).iter().map(|(name, _)| port(&m, name)).collect();
    let (ready, res_ready, res_valid) = (port(&m, "ray_ready"), port(&m, "res_ready"), port(&m, "res_valid"));
    let [arvalid, araddr, arlen, error] =
        ["m_axi_arvalid", "m_axi_araddr", "m_axi_arlen", "mem_error"].map(|n| port(&m, n));
    let observed = OBSERVED.map(|n| port(&m, n));
    let mem_observed = MEMORY_OBSERVED.map(|n| port(&m, n));
    let res: Vec<_> = RESULT_PORTS.iter().map(|n| port(&m, n)).collect();
    let mut model = MemoryModel::new(image.bytes.clone(), SIM_BASE, mem.spec.shape.mem_bits, timing);
    let mut stats = CoreStats { rays: rays.len() as u64, slots: p.slot_count() as u64, ..Default::default() };
    let mut ms = MemoryStats { latency: timing.latency, mem_bits: mem.spec.shape.mem_bits, ..Default::default() };
    let mut results = Vec::with_capacity(rays.len());
    let idle = vec![0i128; ins.len()];
    let mut next = 0;
    let mut limits = RunLimits::new(p, roms, rays.len() as u64, &timing);
    sim.set(res_ready, 1);
    sim.set(mem_ins[0], SIM_BASE as i128);
    while results.len() < rays.len() {
        // A clock the source holds back a ray it has (counted as the on-chip runs count it).
        let stalled = next < rays.len() && stalls.at(stats.cycles);
        let offered = rays.get(next).filter(|_| !stalled);
        let values = offered.map(|r| ray_inputs(r.pixel as u64, &r.ray));
        for (s, v) in ins.iter().zip(values.as_deref().unwrap_or(&idle)) {
            sim.set(*s, *v);
        }
        let bus = model.out();
        let bus_in = [bus.arready as i128, bus.rvalid as i128, bus.rdata as i128, bus.rlast as i128, 0];
        for (s, v) in mem_ins[1..].iter().zip(bus_in) {
            sim.set(*s, v);
        }
        sim.eval();
        let fire = values.is_some() && sim.get(ready) == 1;
        let shown = (sim.get(res_valid) == 1).then(|| res.iter().map(|s| sim.get(*s)).collect::<Vec<i128>>());
        let master = MasterOut {
            arvalid: sim.get(arvalid) == 1,
            araddr: sim.get(araddr) as u64,
            arlen: sim.get(arlen) as u32,
            rready: true,
        };
        sim.tick();
        model.clock(&master);
        stats.cycles += 1;
        stats.stall_cycles += stalled as u64;
        stats.count(&observed.map(|o| sim.get(o)));
        ms.count(&mem_observed.map(|o| sim.get(o)));
        next += fire as usize;
        if let Some(row) = &shown {
            results.push(core_result(row));
            if results.len() % 256 == 0 {
                progress(results.len() as u64);
            }
        }
        if sim.get(error) != 0 {
            return Err(Stopped(format!("clock {}: the read master flagged a memory error", stats.cycles)));
        }
        let walked = stats.visits + stats.culls + stats.busy_cycles;
        limits.check(stats.cycles, shown.is_some(), walked, ms.tri_hits).map_err(|why| {
            Stopped(format!("the core stopped producing results ({} of {}; {why})", results.len(), rays.len()))
        })?;
    }
    (ms.reads, ms.beats) = (model.bursts_taken, model.beats);
    ms.finish(stats.rays, stats.cycles);
    Ok((results, stats, ms))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cores::memory_params::MemorySpec;
    use crate::cores::top::CoreSpec;
    use crate::model::camera::Camera;
    use crate::params::Params;
    use crate::scene::memory::MemoryShape;
    use crate::scene::{Scene, SceneSource};
    use crate::verify::frame::{frame_rays, golden_walk, mismatches};

    fn limits(quiet: u64, staged: u64) -> RunLimits {
        RunLimits {
            quiet,
            walk: 1_000,
            staged,
            walked_before: 0,
            staged_before: 0,
            staged_at_walk: 0,
            last_progress: 0,
        }
    }

    /// A leaf staged a record at a time, far longer than the quiet bound with no node step
    /// (campaign seed 24, case 500) is progress; a clock count past the bound with nothing at
    /// all is not, and neither are more records staged between two steps than the slots hold.
    #[test]
    fn staging_a_long_leaf_is_progress_but_staging_without_end_is_not() {
        let mut l = limits(1_000, 50);
        l.check(1, false, 3, 0).unwrap();
        // 40 records, one every 300 clocks: 12,000 clocks without a step.
        for (cycle, staged) in (1..=12_000u64).map(|c| (1 + c, c / 300)) {
            l.check(cycle, false, 3, staged).unwrap();
        }
        // A test (the leaf in the pipeline) resets the count of records staged.
        l.check(12_002, false, 4, 40).unwrap();
        let staging = (1..=20_000u64).map(|c| (12_002 + c, 40 + c / 300));
        let stopped =
            staging.clone().find_map(|(c, staged)| l.check(c, false, 4, staged).err().map(|why| (staged, why)));
        let (staged, why) = stopped.expect("staging without end is stopped");
        assert_eq!(staged, 40 + 51, "{why}");
        assert!(why.contains("more than the slots hold"), "{why}");
        let mut l = limits(1_000, 50);
        l.check(1, true, 0, 0).unwrap();
        let stopped = (2..3_000).find_map(|c| l.check(c, false, 0, 0).err().map(|why| (c, why)));
        let (cycle, why) = stopped.expect("a run without progress is stopped");
        assert_eq!(cycle, 1_001);
        assert!(why.contains("the last 1000 clocks ago"), "{why}");
    }

    /// Every ray's result is the golden model's, and the walk is `trace_culled`'s step for
    /// step, whatever the memory's latency and pauses.
    #[test]
    fn external_memory_frames_are_exact() {
        let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
        let roms = SceneRoms::of(&scene);
        let rays = frame_rays(&scene, &Camera::default_for(&scene, 10, 10));
        let spec = MemorySpec { node_cache_kb: 1, tri_cache_kb: 1, ..MemorySpec::default() };
        let shape = CoreSpec { slots: 16, ..CoreSpec::default() };
        let p = CoreParams::external(&roms, &shape, spec).unwrap();
        let image = SceneImage::build(&roms, MemoryShape::default()).unwrap();
        let (steps, tests) = golden_walk(&scene, &rays);
        for timing in [
            MemoryTiming::default(),
            MemoryTiming { latency: 200, extra_delay: 30, pause_in_256: 60, seed: 7, ..MemoryTiming::default() },
        ] {
            let (results, stats, ms) =
                simulate_external(&p, &roms, &image, &rays, timing, &Stalls::none(), &|_| ()).unwrap();
            assert_eq!(mismatches(&scene, &rays, &results), 0, "{timing:?}");
            assert_eq!((stats.visits + stats.culls, stats.busy_cycles), (steps, tests), "{timing:?}");
            assert!(ms.node_hits < ms.node_lookups && ms.tri_hits < ms.tri_lookups, "{ms:?}");
            eprintln!("{timing:?}: {} cycles, {:?}", stats.cycles, ms);
        }
    }

    /// The clocks the source holds a ray back are counted as the on-chip runs count them
    /// (`stall_cycles`; it was 0 on a stalled feed, where Verilator's testbench counted 1,814):
    /// at least the stalls among the first clocks, one per ray (rays remain at least that
    /// long), at most those of the whole run, and none without stalls.
    #[test]
    fn a_stalled_source_is_counted_through_an_external_core() {
        let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
        let roms = SceneRoms::of(&scene);
        let rays = frame_rays(&scene, &Camera::default_for(&scene, 6, 6));
        let spec = MemorySpec { node_cache_kb: 1, tri_cache_kb: 1, ..MemorySpec::default() };
        let p = CoreParams::external(&roms, &CoreSpec { slots: 8, ..CoreSpec::default() }, spec).unwrap();
        let image = SceneImage::build(&roms, MemoryShape::default()).unwrap();
        let stalls = Stalls::random(40, 5);
        let run = |stalls: &Stalls| {
            simulate_external(&p, &roms, &image, &rays, MemoryTiming::default(), stalls, &|_| ()).unwrap()
        };
        let (results, stats, _) = run(&stalls);
        assert_eq!(mismatches(&scene, &rays, &results), 0);
        let hits = |clocks: u64| (0..clocks).filter(|&c| stalls.at(c)).count() as u64;
        assert!(
            (hits(rays.len() as u64)..=hits(stats.cycles)).contains(&stats.stall_cycles),
            "{} stalled clocks of {}",
            stats.stall_cycles,
            stats.cycles
        );
        assert_eq!(run(&Stalls::none()).1.stall_cycles, 0);
    }

    /// A leaf spanning more lines than the triangle cache has sets (the Cornell box in one
    /// 32-triangle leaf, a 1 KB cache of four 2-way sets or eight 1-way ones) evicts its own
    /// lines while it is fetched, yet finishes: what a pass staged stays staged (DECISIONS 109).
    /// Such scenes were refused before (DECISIONS 103); with every pass fetching the whole
    /// leaf again, this one hangs.
    #[test]
    fn a_leaf_larger_than_the_triangle_cache_finishes() {
        let params = Params { leaf_size: 64, ..Params::default() };
        let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &params).unwrap();
        let roms = SceneRoms::of(&scene);
        let rays = frame_rays(&scene, &Camera::default_for(&scene, 6, 6));
        let (steps, tests) = golden_walk(&scene, &rays);
        for ways in [1, 2] {
            let spec = MemorySpec { node_cache_kb: 1, tri_cache_kb: 1, ways, ..MemorySpec::default() };
            let p = CoreParams::external(&roms, &CoreSpec { slots: 8, ..CoreSpec::default() }, spec).unwrap();
            let mem = p.mem.as_ref().unwrap();
            let (layout, words) = &roms.node;
            let leaves = words.iter().filter(|w| w.get(layout.field("axis")) == 3);
            let largest = leaves.map(|w| w.get(layout.field("count"))).max().unwrap() as usize;
            let lines = largest.div_ceil(mem.layout.tris_per_line as usize);
            assert!(lines > mem.tri.sets as usize, "the case it guards: {lines} lines, {} sets", mem.tri.sets);
            let image = SceneImage::build(&roms, spec.shape).unwrap();
            let timing =
                MemoryTiming { latency: 60, extra_delay: 20, pause_in_256: 50, seed: 3, ..MemoryTiming::default() };
            let (results, stats, _) =
                simulate_external(&p, &roms, &image, &rays, timing, &Stalls::none(), &|_| ()).unwrap();
            assert_eq!(mismatches(&scene, &rays, &results), 0, "{ways} ways");
            assert_eq!((stats.visits + stats.culls, stats.busy_cycles), (steps, tests), "{ways} ways");
        }
    }

    /// A tree with fewer nodes than a node line holds (the five-triangle `thin`, 8-byte node
    /// records at a 32-bit port: 16 to a line, node numbers of 3 bits): the core builds and
    /// every ray is right. The campaign's first external finding was a panic building it.
    #[test]
    fn a_tree_smaller_than_a_node_line_works() {
        let params = Params { n: 24, m: 51, leaf_size: 1, ..Params::default() };
        let scene = Scene::load(&SceneSource::Builtin("thin".into()), &params).unwrap();
        let roms = SceneRoms::of(&scene);
        let rays = frame_rays(&scene, &Camera::default_for(&scene, 4, 4));
        let spec = MemorySpec { shape: MemoryShape { mem_bits: 32, line_bytes: 128 }, ..MemorySpec::default() };
        let p = CoreParams::external(&roms, &CoreSpec::default(), spec).unwrap();
        assert!(p.mem.as_ref().unwrap().node_line_shift() > p.trav.node_bits, "the case it guards");
        let image = SceneImage::build(&roms, spec.shape).unwrap();
        let (results, _, _) =
            simulate_external(&p, &roms, &image, &rays, MemoryTiming::default(), &Stalls::none(), &|_| ()).unwrap();
        assert_eq!(mismatches(&scene, &rays, &results), 0);
    }
}
