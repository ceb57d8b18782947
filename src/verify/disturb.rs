//! The core driven port by port in the cycle simulator (`rtl::sim`), as the HDL testbenches
//! drive it, with what a system around it does besides feeding rays: a consumer that is not
//! always ready (`res_ready` low on the cycles of a pattern) and one-clock resets at chosen
//! cycles, optionally from a scrambled state (every register and RAM random).
//!
//! The rules checked (docs/CORE.md, "Result port" and "Reset"): a result is taken on a clock
//! with `res_valid` and `res_ready` both 1, and while it waits its ports hold still; a clock
//! with `rst` high transfers nothing and leaves nothing in flight — after it, the source starts
//! the frame again and every ray must get exactly one right result, with no result left over
//! from before the reset.

use super::feed::Stalls;
use super::frame::{CoreResult, CoreStats, OBSERVED, RESULT_PORTS, core_result, port};
use crate::cores::top::{CoreParams, core_inputs, core_module, ray_inputs};
use crate::rtl::Module;
use crate::rtl::sim::Sim;
use crate::scene::images::SceneRoms;
use crate::verify::frame::PixelRay;

/// What happens to the core besides the frame's rays.
#[derive(Clone, Debug, Default)]
pub struct Disturb {
    /// The consumer holds `res_ready` low on cycle c iff `sink.at(c)`.
    pub sink: Stalls,
    /// Testbench cycles (ascending) with `rst` high for one clock.
    pub resets: Vec<u64>,
    /// Fill every register and RAM with random bits (seeded by this and the cycle) just
    /// before each reset: a reset from any state.
    pub scramble: Option<u64>,
}

impl Disturb {
    pub fn none() -> Disturb {
        Disturb::default()
    }
}

/// A run of `simulate_cycle`: the results after the last reset (in the order taken), the
/// counts over the whole run, and the results taken before the last reset.
pub struct CycleRun {
    pub results: Vec<CoreResult>,
    pub stats: CoreStats,
    pub before_reset: Vec<CoreResult>,
}

/// Streams `rays` through the core in the cycle simulator, driving its ports directly: each
/// cycle the next ray (in the order given) is on the ports, with `ray_valid` high unless
/// `stalls` holds it back; `d` drives `res_ready` and `rst`. Panics (a test failure) if a
/// waiting result changes, or if the core stops producing results.
pub fn simulate_cycle(
    p: &CoreParams,
    scene: &SceneRoms,
    rays: &[PixelRay],
    stalls: &Stalls,
    d: &Disturb,
    progress: &dyn Fn(u64),
) -> CycleRun {
    let m = core_module(p, scene);
    let mut sim = Sim::new(&m);
    let ins: Vec<_> = core_inputs(p).iter().map(|(name, _)| port(&m, name)).collect();
    let ready = port(&m, "ray_ready");
    // Absent from cores before result backpressure: there a result not taken is lost.
    let res_ready = m.inputs.iter().find(|&&i| m.sig(i).name == "res_ready").map(|&i| m.handle(i));
    let observed = OBSERVED.map(|n| port(&m, n));
    let res_valid = port(&m, "res_valid");
    let res: Vec<_> = RESULT_PORTS.iter().map(|n| port(&m, n)).collect();
    let mut stats = CoreStats { rays: rays.len() as u64, slots: p.slot_count() as u64, ..Default::default() };
    let (mut results, mut before_reset) = (Vec::with_capacity(rays.len()), Vec::new());
    let mut resets = d.resets.iter().copied().peekable();
    let mut next = 0;
    let mut waiting: Option<Vec<i128>> = None;
    let idle = vec![0i128; ins.len()];
    let limit = 400_000 + 20_000 * rays.len() as u64 + d.resets.last().copied().unwrap_or(0);
    while results.len() < rays.len() {
        let mut values = rays.get(next).map(|r| ray_inputs(r.pixel as u64, &r.ray));
        let stalled = values.is_some() && stalls.at(stats.cycles);
        if let (true, Some(v)) = (stalled, values.as_mut()) {
            // The ray stays on the data ports; only ray_valid drops.
            v[0] = 0;
        }
        for (s, v) in ins.iter().zip(values.as_deref().unwrap_or(&idle)) {
            sim.set(*s, *v);
        }
        let sink_ready = !d.sink.at(stats.cycles);
        if let Some(r) = res_ready {
            sim.set(r, sink_ready as i128);
        }
        if resets.next_if_eq(&stats.cycles).is_some() {
            if let Some(seed) = d.scramble {
                sim.scramble(seed ^ stats.cycles.wrapping_mul(0x9e37_79b9_7f4a_7c15));
            }
            // Nothing is transferred in a reset clock; the frame starts again after it.
            sim.reset = true;
            sim.tick();
            sim.reset = false;
            stats.cycles += 1;
            stats.stall_cycles += stalled as u64;
            stats.count(&observed.map(|o| sim.get(o)));
            before_reset.append(&mut results);
            (next, waiting) = (0, None);
            continue;
        }
        sim.eval();
        let fire = values.is_some() && !stalled && sim.get(ready) == 1;
        let shown = (sim.get(res_valid) == 1).then(|| res.iter().map(|s| sim.get(*s)).collect::<Vec<i128>>());
        if let (Some(held), Some(now)) = (&waiting, &shown) {
            assert_eq!(held, now, "cycle {}: a result changed while it waited for res_ready", stats.cycles);
        }
        // The consumer takes what is shown when it is ready (with no `res_ready` port, a result
        // shown while it is not ready is gone).
        let taken = shown.as_ref().filter(|_| sink_ready).cloned();
        waiting = shown.filter(|_| !sink_ready && res_ready.is_some());
        sim.tick();
        stats.cycles += 1;
        stats.stall_cycles += stalled as u64;
        // Observed after the edge, as the testbenches do (Verilator's timing mode does not
        // show these before it).
        stats.count(&observed.map(|o| sim.get(o)));
        next += fire as usize;
        if let Some(row) = taken {
            results.push(core_result(&row));
            if results.len() % 256 == 0 {
                progress(results.len() as u64);
            }
        }
        assert!(stats.cycles < limit, "the core stopped producing results ({} of {})", results.len(), rays.len());
    }
    CycleRun { results, stats, before_reset }
}

/// The ray of the core's shortest latency: its origin just past the scene box on an axis with
/// room, pointing away, so the box exit finds it missing and it finishes without a node step.
/// None when the box fills the grid on every axis (no such ray exists).
pub fn min_latency_ray(p: &CoreParams, scene: &SceneRoms) -> Option<crate::model::golden::GridRay> {
    let n = p.isect.n;
    let axis = (0..3).find(|&a| scene.box_hi[a] + 1 < 1i64 << n)?;
    let mut o = [0i64; 3];
    o[axis] = scene.box_hi[axis] + 1;
    // The direction is read by the pipeline only; a tiny positive one on every axis, with
    // its reciprocals saturated as the golden model's are.
    let lim = (1i128 << (p.trav.inv_width() - 1)) - 1;
    Some(crate::model::golden::GridRay { o, w: [1; 3], inv: [lim; 3] })
}

/// The core's shortest latency: clocks from the clock a ray is taken (`ray_valid` and
/// `ray_ready` high) to the first clock its result is shown (`res_valid`), for
/// `min_latency_ray` in an idle core `m` (the core of `p`, with or without observation ports).
/// Every other ray takes longer (it adds node steps, leaves, the pipeline, waits).
pub fn min_latency(m: &Module, p: &CoreParams, scene: &SceneRoms) -> Option<u64> {
    let ray = min_latency_ray(p, scene)?;
    let mut sim = Sim::new(m);
    let ins: Vec<_> = core_inputs(p).iter().map(|(name, _)| port(m, name)).collect();
    let (ready, res_valid) = (port(m, "ray_ready"), port(m, "res_valid"));
    sim.set(port(m, "res_ready"), 1);
    let values = ray_inputs(0, &ray);
    let mut taken = None;
    for cycle in 0..10_000u64 {
        if taken.is_none() {
            for (s, v) in ins.iter().zip(&values) {
                sim.set(*s, *v);
            }
        } else {
            sim.set(ins[0], 0);
        }
        sim.eval();
        if sim.get(res_valid) == 1 {
            return taken.map(|t| cycle - t);
        }
        if taken.is_none() && sim.get(ready) == 1 {
            taken = Some(cycle);
        }
        sim.tick();
    }
    None
}

/// `simulate_rust` in the cycle simulator (`rtl::sim`), driving the core's ports directly as
/// the HDL testbenches do (`simulate_cycle` with a consumer always ready and no
/// reset): results in the order they came out.
pub fn simulate_rust_cycle(
    p: &CoreParams,
    scene: &SceneRoms,
    rays: &[PixelRay],
    stalls: &Stalls,
    progress: &dyn Fn(u64),
) -> (Vec<CoreResult>, CoreStats) {
    let run = simulate_cycle(p, scene, rays, stalls, &Disturb::none(), progress);
    (run.results, run.stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::camera::Camera;
    use crate::params::Params;
    use crate::render::fast::FastGolden;
    use crate::rng::SplitMix64;
    use crate::scene::{Scene, SceneSource};
    use crate::verify::feed::feed_order;
    use crate::verify::frame::{frame_rays, mismatches, simulate_rust};

    fn setup(name: &str, w: u32, h: u32) -> (Scene, SceneRoms, CoreParams, Vec<PixelRay>) {
        let scene = Scene::load(&SceneSource::Builtin(name.into()), &Params::default()).unwrap();
        let roms = SceneRoms::of(&scene);
        let p = CoreParams::new(&roms, 16, 1, crate::cores::clock::DEFAULT_TARGET_MHZ);
        let rays = feed_order(&frame_rays(&scene, &Camera::default_for(&scene, w, h)), Some(5));
        (scene, roms, p, rays)
    }

    /// Every result taken before a reset is still right for its ray (a reset loses rays in
    /// flight, never corrupts what already left).
    fn all_right(scene: &Scene, rays: &[PixelRay], results: &[CoreResult]) -> bool {
        let g = FastGolden::new(scene);
        results
            .iter()
            .all(|(id, hit)| rays.iter().find(|r| r.pixel as u64 == *id).is_some_and(|r| g.trace(&r.ray).0 == *hit))
    }

    /// A consumer ready on 30 % of the clocks, a source stalling on 20 %: every ray gets
    /// exactly one right result, results wait unchanged, and the consumer is what limits
    /// the frame (the core held rays back rather than lose results).
    #[test]
    fn a_slow_consumer_loses_nothing() {
        let (scene, roms, p, rays) = setup("teapot", 14, 14);
        let d = Disturb { sink: Stalls::random(70, 9), ..Disturb::none() };
        let run = simulate_cycle(&p, &roms, &rays, &Stalls::random(20, 4), &d, &|_| {});
        assert_eq!(mismatches(&scene, &rays, &run.results), 0);
        let free = simulate_cycle(&p, &roms, &rays, &Stalls::random(20, 4), &Disturb::none(), &|_| {});
        assert_eq!(mismatches(&scene, &rays, &free.results), 0);
        // Results can leave only on the 30 % of clocks the consumer is ready.
        assert!(
            run.stats.cycles * 3 / 10 >= rays.len() as u64 && run.stats.cycles > free.stats.cycles,
            "{} vs {}",
            run.stats.cycles,
            free.stats.cycles
        );
    }

    /// A consumer away for 3,000 clocks of every 4,096: the result queue fills to its depth
    /// and the done queues back up behind it, and still every ray gets exactly one right
    /// result (a credit promised beyond the queue's depth would overwrite a waiting result).
    #[test]
    fn a_consumer_away_for_long_loses_nothing() {
        let (scene, roms, _, rays) = setup("teapot", 14, 14);
        // More slots than the queue is deep (with 16 they could never overfill it).
        let p = CoreParams::new(&roms, 64, 2, crate::cores::clock::DEFAULT_TARGET_MHZ);
        let d = Disturb { sink: Stalls::block(3_000), ..Disturb::none() };
        let run = simulate_cycle(&p, &roms, &rays, &Stalls::none(), &d, &|_| {});
        assert_eq!(mismatches(&scene, &rays, &run.results), 0);
        assert_eq!(run.results.len(), rays.len());
    }

    /// The shortest latency is a real one and a bound: the box-missing ray's result comes
    /// after it, and no ray of a frame fed one at a time into the idle core is faster.
    #[test]
    fn the_shortest_latency_bounds_every_ray() {
        let (_, roms, p, rays) = setup("cornell", 6, 6);
        let min = min_latency(&core_module(&p, &roms), &p, &roms).expect("the Cornell box leaves room on an axis");
        assert!(min > 10, "{min}");
        for r in rays.iter().take(8) {
            let run = simulate_cycle(&p, &roms, std::slice::from_ref(r), &Stalls::none(), &Disturb::none(), &|_| {});
            // Taken on clock 0 (the port is ready and the ray offered at once); its result
            // shown and taken on the last clock counted.
            assert!(run.stats.cycles > min, "ray {}: {} clocks, the minimum {min}", r.pixel, run.stats.cycles - 1);
        }
    }

    /// Seeded reset clocks spread over the first pass of the frame.
    fn reset_points(seed: u64, count: usize, span: u64) -> Vec<u64> {
        let mut rng = SplitMix64(seed);
        let mut v: Vec<u64> = (0..count).map(|_| 1 + rng.below(span)).collect();
        v.sort();
        v.dedup();
        v
    }

    /// One-clock resets at random points of a frame (rays in the pipeline, in the slots,
    /// results waiting), with a consumer that stalls: after the last one every ray gets
    /// exactly one right result, and nothing from before a reset comes out after it.
    #[test]
    fn one_clock_resets_leave_nothing_in_flight() {
        let (scene, roms, p, rays) = setup("teapot", 12, 12);
        for seed in [1, 2, 3] {
            let resets = reset_points(seed, 3, 20 * rays.len() as u64);
            let d = Disturb { sink: Stalls::random(30, seed), resets: resets.clone(), scramble: None };
            let run = simulate_cycle(&p, &roms, &rays, &Stalls::random(10, seed), &d, &|_| {});
            assert_eq!(mismatches(&scene, &rays, &run.results), 0, "seed {seed}, resets at {resets:?}");
            assert!(all_right(&scene, &rays, &run.before_reset), "seed {seed}");
        }
    }

    /// A reset from any state: every register and RAM scrambled, then one clock of reset
    /// (three times in a frame): the frame after it is right.
    #[test]
    fn one_clock_of_reset_from_a_scrambled_state() {
        let (scene, roms, p, rays) = setup("cornell", 10, 10);
        for seed in [7, 8] {
            let resets = reset_points(seed, 3, 20 * rays.len() as u64);
            let d = Disturb { resets: resets.clone(), scramble: Some(seed), ..Disturb::none() };
            let run = simulate_cycle(&p, &roms, &rays, &Stalls::none(), &d, &|_| {});
            assert_eq!(mismatches(&scene, &rays, &run.results), 0, "seed {seed}, resets at {resets:?}");
        }
    }

    /// Shuffled rays and a stalling source, in both engines: the same results in the same
    /// (arrival) order, the same counts; every result right; the rays really went in shuffled
    /// and the stalls really cost cycles.
    #[test]
    fn shuffled_stalled_frames_run_alike_in_both_engines() {
        let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params { n: 29, m: 32, ..Params::default() })
            .unwrap();
        let roms = SceneRoms::of(&scene);
        let p = CoreParams::new(&roms, 8, 1, crate::cores::clock::DEFAULT_TARGET_MHZ);
        let rays = frame_rays(&scene, &Camera::default_for(&scene, 10, 8));
        let fed = feed_order(&rays, Some(11));
        let stalls = Stalls::random(40, 5);
        let (results, stats) = simulate_rust(&p, &roms, &fed, &stalls, &|_| {});
        let (cycle_results, cycle_stats) = simulate_rust_cycle(&p, &roms, &fed, &stalls, &|_| {});
        assert_eq!(cycle_results, results);
        assert_eq!(
            (
                cycle_stats.cycles,
                cycle_stats.busy_cycles,
                cycle_stats.stall_cycles,
                cycle_stats.visits,
                cycle_stats.culls
            ),
            (stats.cycles, stats.busy_cycles, stats.stall_cycles, stats.visits, stats.culls)
        );
        assert_eq!(mismatches(&scene, &rays, &results), 0);
        let arrival: Vec<u64> = results.iter().map(|r| r.0).collect();
        let mut sorted = arrival.clone();
        sorted.sort();
        assert_ne!(arrival, sorted, "the rays were fed shuffled");
        let (_, plain) = simulate_rust(&p, &roms, &fed, &Stalls::none(), &|_| {});
        assert_eq!(plain.stall_cycles, 0);
        // About 40 % of the cycles in which rays remained, which are at least 4 per ray (the
        // core takes one ray per 4 clocks at most): over 30 % of those.
        assert!(stats.stall_cycles * 10 >= 3 * 4 * stats.rays, "{stats:?}");
        // Whether 40 % stalls lengthen so short a frame depends on its slowest ray: the slots'
        // order and timing change with the feed, and the frame's length with them (898 clocks
        // either way with the free list; with the result port's output register, 903 stalled
        // against 908 without). A source that stalls 90 % of the time holds the last rays back
        // past any such change.
        let (_, heavy) = simulate_rust(&p, &roms, &fed, &Stalls::random(90, 5), &|_| {});
        assert!(heavy.cycles > plain.cycles, "{stats:?} {heavy:?} {plain:?}");
    }
}
