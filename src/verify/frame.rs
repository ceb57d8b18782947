//! Whole frames through the generated core (`fxrt sim`): every pixel's ray that reaches the
//! scene box is streamed into the core — in pixel order, or shuffled and with random input
//! stalls (`verify::feed`) — and each result is matched by its ray id (the pixel number) to its
//! ray and compared with the golden model's (`render::fast`), pixel by pixel. Nothing assumes
//! that results leave the core in the order the rays entered it.

use crate::cores::top::{CoreParams, core_inputs, core_module, ray_inputs};
use crate::error::{Error, Result};
use crate::model::camera::Camera;
use crate::model::golden::{Golden, GridRay, Hit};
use crate::model::ray::quantize_ray;
use crate::render::fast::FastGolden;
use crate::rtl::batch::BatchSim;
use crate::rtl::{Module, Ty};
use crate::scene::Scene;
use crate::scene::images::SceneRoms;
use crate::verify::feed::Stalls;
use crate::verify::simulators::{Bench, Simulator};
use crate::verify::testbench::{Stream, parse_results, stream_files};
use serde::Serialize;
use std::path::Path;

/// A ray of the frame: its pixel (row-major) and its grid form.
#[derive(Clone, Copy, Debug)]
pub struct PixelRay {
    pub pixel: u32,
    pub ray: GridRay,
}

/// The rays of every pixel that reach the scene box (the others miss without the core).
pub fn frame_rays(scene: &Scene, cam: &Camera) -> Vec<PixelRay> {
    let g = Golden::new(scene);
    let mut v = Vec::new();
    for py in 0..cam.height {
        for px in 0..cam.width {
            if let Some(q) = quantize_ray(scene, &g, &cam.ray(px, py)) {
                v.push(PixelRay { pixel: py * cam.width + px, ray: q.ray });
            }
        }
    }
    v
}

/// One result of the core: the ray id and its closest hit (triangle table number).
pub type CoreResult = (u64, Option<Hit>);

/// What a simulation of the core measured.
#[derive(Clone, Debug, Default, Serialize)]
pub struct CoreStats {
    pub cycles: u64,
    pub rays: u64,
    /// Cycles in which a triangle entered the intersection pipeline.
    pub busy_cycles: u64,
    pub max_stack_depth: u32,
    /// Node visits and culled node entries of every traversal unit (the Rust simulators count
    /// them, the HDL testbenches do not).
    pub visits: u64,
    pub culls: u64,
    /// Sum over cycles of the slots holding a ray, and the core's slot count.
    pub occupied_sum: u64,
    pub slots: u64,
    /// Cycles the ray source held back although it had a ray (`Stalls`).
    pub stall_cycles: u64,
}

impl CoreStats {
    fn new(rays: u64, slots: u64) -> CoreStats {
        CoreStats { rays, slots, ..Default::default() }
    }

    /// One cycle's observation ports: triangle in the pipeline, stack depth, visits, culls,
    /// occupied slots.
    pub(crate) fn count(&mut self, row: &[i128]) {
        self.busy_cycles += row[0] as u64;
        self.max_stack_depth = self.max_stack_depth.max(row[1] as u32);
        self.visits += row[2] as u64;
        self.culls += row[3] as u64;
        self.occupied_sum += row[4] as u64;
    }

    pub fn cycles_per_ray(&self) -> f64 {
        self.cycles as f64 / self.rays.max(1) as f64
    }
    pub fn rays_per_clock(&self) -> f64 {
        self.rays as f64 / self.cycles.max(1) as f64
    }
    pub fn fill(&self) -> f64 {
        self.busy_cycles as f64 / self.cycles.max(1) as f64
    }
    /// Triangles that entered the pipeline per ray.
    pub fn triangle_tests_per_ray(&self) -> f64 {
        self.busy_cycles as f64 / self.rays.max(1) as f64
    }
    /// Node steps (visits and culled entries) per ray.
    pub fn node_steps_per_ray(&self) -> f64 {
        (self.visits + self.culls) as f64 / self.rays.max(1) as f64
    }
    /// The mean fraction of the core's ray slots holding a ray.
    pub fn slot_occupancy(&self) -> f64 {
        self.occupied_sum as f64 / (self.cycles.max(1) * self.slots.max(1)) as f64
    }
}

/// Observation ports of the core, in the order `CoreStats::count` reads them.
pub const OBSERVED: [&str; 5] = ["busy", "stack_depth", "visits", "culls", "occupied"];

pub(crate) fn port(m: &Module, name: &str) -> crate::rtl::Sig {
    let id = m.outputs.iter().find(|o| o.0 == name).map(|o| o.1);
    let id = id.or_else(|| m.inputs.iter().copied().find(|&i| m.sig(i).name == name));
    m.handle(id.unwrap_or_else(|| panic!("{}: no port {name}", m.name)))
}

/// The core with its ray source in one netlist, so the batched simulator can run it: one ROM
/// per ray field holding every ray (in the order given: the feed order), a ray counter that
/// advances when the core takes a ray, and the core. The ROMs are read at the counter's next
/// value, so a ray is on the core's inputs in the cycle after the counter reaches it; the
/// source starts one cycle late for that. With `stalls`, a one-bit ROM of the stall pattern,
/// read at a free-running cycle counter, holds `ray_valid` low on the pattern's cycles; the
/// output `source_stall` is 1 in the cycle after one in which the source held back a ray.
pub fn frame_harness(p: &CoreParams, scene: &SceneRoms, rays: &[PixelRay], stalls: &Stalls) -> Module {
    let mut m = Module::new("fxrt_frame");
    let count = rays.len().max(1);
    let bits = crate::scene::rom::rom_addr_bits(count + 1);
    let idx = m.reg("ray_index", Ty::u(bits), Some(0));
    let started = m.reg("started", Ty::BIT, Some(0));
    let one_bit = m.konst("one", Ty::BIT, 1);
    m.connect(started, one_bit, None);
    let last = m.konst("ray_count", idx.ty, rays.len() as i128);
    let more = m.lt("more", idx, last);
    let offer = m.and("offer", started, more);
    let (valid, stalled) = if stalls.is_none() {
        (offer, None)
    } else {
        // Harness cycle h is the testbenches' cycle h − 1: the counter is h mod PERIOD, and
        // the ROM's synchronous read shows pattern[(h − 1) mod PERIOD] in cycle h.
        let cycle = m.reg("stall_cycle", Ty::u(Stalls::PERIOD_BITS), Some(0));
        let cycle_one = m.konst("stall_cycle_one", cycle.ty, 1);
        let cycle_inc = m.add("stall_cycle_inc", cycle, cycle_one);
        m.connect(cycle, cycle_inc, None);
        let words = stalls.period().into_iter().map(u128::from).collect();
        let rom = m.rom("stall_pattern", 1, words);
        let stall = m.rom_read("stall", rom, cycle);
        let held = m.and("held", offer, stall);
        let go = m.not("go", stall);
        let stalled = m.reg("stalled", Ty::BIT, Some(0));
        m.connect(stalled, held, None);
        (m.and("valid", offer, go), Some(stalled))
    };
    let ready = m.wire("ready", Ty::BIT);
    let fire = m.and("fire", valid, ready);
    let one = m.konst("index_one", idx.ty, 1);
    let inc = m.add("index_inc", idx, one);
    let idx_next = m.mux("index_next", fire, inc, idx);
    m.connect(idx, idx_next, None);
    let addr = m.resize("ray_addr", idx_next, crate::scene::rom::rom_addr_bits(count));
    let values: Vec<Vec<i128>> = rays.iter().map(|r| ray_inputs(r.pixel as u64, &r.ray)).collect();
    let mut ins = vec![valid];
    for (k, (name, ty)) in core_inputs(p).iter().enumerate().skip(1) {
        let words = values.iter().map(|v| ty.wrap(v[k])).collect::<Vec<u128>>();
        let words = if words.is_empty() { vec![0] } else { words };
        let rom = m.rom(&format!("rays_{name}"), ty.width, words);
        let raw = m.rom_read(&format!("ray_{name}"), rom, addr);
        ins.push(if ty.signed { m.un(&format!("ray_{name}_s"), crate::rtl::UnOp::AsSigned, raw) } else { raw });
    }
    // The consumer is always ready: every result is taken the clock it is shown.
    ins.push(m.konst("res_ready", Ty::BIT, 1));
    let core = std::rc::Rc::new(core_module(p, scene));
    let outs = m.instance("u_core", &core, &ins);
    let pos = |name: &str| core.outputs.iter().position(|o| o.0 == name).expect("core port");
    m.drive(ready, outs[pos("ray_ready")]);
    for name in ["res_valid", "res_id", "res_hit", "res_tri", "res_t", "res_u", "res_v"].into_iter().chain(OBSERVED) {
        m.output(name, outs[pos(name)]);
    }
    if let Some(s) = stalled {
        m.output("source_stall", s);
    }
    m
}

/// Streams `rays` through the core in the batched Rust simulator (`rtl::batch`) in the order
/// given, with the ray source in the netlist (`frame_harness`) holding back on the cycles of
/// `stalls`. The same results, in the same order, and counts as `disturb::simulate_rust_cycle` and the
/// HDL testbenches, several times faster. `progress` gets the number of results now and then.
pub fn simulate_rust(
    p: &CoreParams,
    scene: &SceneRoms,
    rays: &[PixelRay],
    stalls: &Stalls,
    progress: &dyn Fn(u64),
) -> (Vec<CoreResult>, CoreStats) {
    if rays.is_empty() {
        return (Vec::new(), CoreStats::default());
    }
    // Cycle c of the harness is cycle c − 1 of a testbench driving the core directly.
    collect_batched(&frame_harness(p, scene, rays, stalls), rays.len(), p.slot_count(), 1, progress)
}

/// Runs a design without inputs whose outputs are the core's results and observations (the
/// frame harness, or the core with its ray generator) in the batched simulator until `count`
/// results came out, in the order they came out. The first `skip` cycles are not counted. An
/// output `source_stall`, if the design has one, counts the source's stall cycles.
pub fn collect_batched(
    m: &Module,
    count: usize,
    slots: u32,
    skip: u64,
    progress: &dyn Fn(u64),
) -> (Vec<CoreResult>, CoreStats) {
    let names = ["res_valid", "res_id", "res_hit", "res_tri", "res_t", "res_u", "res_v"].into_iter().chain(OBSERVED);
    let order: Vec<usize> = names.map(|n| m.outputs.iter().position(|o| o.0 == n).expect("a core output")).collect();
    let stall_out = m.outputs.iter().position(|o| o.0 == "source_stall");
    let mut sim = BatchSim::new(m, 256).expect("a design without inputs");
    let mut stats = CoreStats::new(count as u64, slots as u64);
    let mut results: Vec<CoreResult> = Vec::with_capacity(count);
    let mut all = vec![0i128; m.outputs.len()];
    let mut finished: Option<u64> = None;
    let mut cycles = 0u64;
    while finished.is_none() {
        // A few batches at a time: a small frame ends after a few thousand cycles, and every
        // cycle advanced past its last result is simulated for nothing.
        sim.advance(
            1 << 10,
            |_, _| 0,
            |c, k, v| {
                all[k] = v;
                if k + 1 < all.len() || finished.is_some() || (c as u64) < skip {
                    return;
                }
                let row: Vec<i128> = order.iter().map(|&i| all[i]).collect();
                // Taken in the clock after the one that showed it (as the testbenches count).
                cycles = c as u64 + 2 - skip;
                stats.count(&row[7..]);
                stats.stall_cycles += stall_out.map_or(0, |i| all[i] as u64);
                if row[0] == 1 {
                    results.push(core_result(&row[1..7]));
                    if results.len() == count {
                        finished = Some(cycles);
                    }
                }
            },
        );
        progress(results.len() as u64);
        assert!(cycles < 1 << 40, "the core stopped producing results");
    }
    stats.cycles = finished.unwrap_or(cycles);
    (results, stats)
}

/// Rays and results that do not match, whatever order the results came in: each result is
/// matched to the ray with its id (the pixel number) and counts once if it differs from the
/// golden model's (triangle, t, u, v), if no ray has its id, or if an earlier result had the
/// same id; each ray without a result counts once too. 0 means every ray got exactly one
/// result and every result is right.
pub fn mismatches(scene: &Scene, rays: &[PixelRay], results: &[CoreResult]) -> u64 {
    let g = FastGolden::new(scene);
    let by_id: std::collections::HashMap<u64, usize> =
        rays.iter().enumerate().map(|(k, r)| (r.pixel as u64, k)).collect();
    let mut seen = vec![false; rays.len()];
    let mut bad = 0u64;
    for (id, hit) in results {
        match by_id.get(id) {
            Some(&k) if !seen[k] => {
                seen[k] = true;
                bad += (*hit != g.trace(&rays[k].ray).0) as u64;
            }
            // A second result for a ray, or a result for no ray.
            _ => bad += 1,
        }
    }
    // Two rays with one id: only one can be matched; the other counts as missing below.
    bad + seen.iter().filter(|&&s| !s).count() as u64
}

/// The golden culled walk's totals over `rays` (`Golden::trace_culled`, the hardware's walk):
/// node steps (visits and culled entries) and triangle tests — what the core's observation
/// ports must count, whatever its shape and the order the rays came in.
pub fn golden_walk(scene: &Scene, rays: &[PixelRay]) -> (u64, u64) {
    let g = Golden::new(scene);
    rays.iter().fold((0, 0), |(steps, tests), r| {
        let st = g.trace_culled(scene, &r.ray).1;
        (steps + (st.nodes + st.culled) as u64, tests + st.tri_tests as u64)
    })
}

/// W·H input triangle numbers (−1 for a miss) from the core's results, placed by the ray id
/// each result carries.
pub fn ids_image(scene: &Scene, width: u32, height: u32, results: &[CoreResult]) -> Vec<i32> {
    let mut ids = vec![-1i32; (width * height) as usize];
    for (id, hit) in results {
        if let (Some(px), Some(h)) = (ids.get_mut(*id as usize), hit) {
            *px = scene.tri_ids.get(h.tri as usize).map_or(-2, |&t| t as i32);
        }
    }
    ids
}

/// The binary picture of seed 001 figure 3.7: hits white, misses black.
pub fn binary_png(width: u32, height: u32, ids: &[i32]) -> Vec<u8> {
    let rgb: Vec<u8> = ids.iter().flat_map(|&i| if i >= 0 { [255u8; 3] } else { [0u8; 3] }).collect();
    crate::render::encode_png(width, height, &rgb)
}

/// A progress bar over results (hidden for small frames).
pub fn progress_bar(total: u64, what: &str) -> indicatif::ProgressBar {
    let bar = if total >= 4096 { indicatif::ProgressBar::new(total) } else { indicatif::ProgressBar::hidden() };
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} rays ({eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message(what.to_string());
    bar
}

/// Outputs a stream testbench checks and writes back, in order.
pub const RESULT_PORTS: [&str; 6] = ["res_id", "res_hit", "res_tri", "res_t", "res_u", "res_v"];

/// A result from the values of `RESULT_PORTS`.
pub(crate) fn core_result(r: &[i128]) -> CoreResult {
    let hit = (r[1] == 1).then(|| Hit { tri: r[2] as u32, t: r[3] as i64, u: r[4] as i64, v: r[5] as i64 });
    (r[0] as u64, hit)
}

/// A result as the values of `RESULT_PORTS`.
fn result_row(id: u64, hit: Option<Hit>) -> Vec<i128> {
    match hit {
        Some(h) => vec![id as i128, 1, h.tri as i128, h.t as i128, h.u as i128, h.v as i128],
        None => vec![id as i128, 0, 0, 0, 0, 0],
    }
}

/// What a stream testbench feeds and checks for a frame: the core, the rays' input values in
/// feed order, the expected results by ray id, the stall pattern and a cycle limit. Public so a
/// test can corrupt it and see the testbench fail.
pub struct FrameStream {
    pub core: Module,
    /// Every input port but `ray_valid`, per ray, in feed order.
    pub rays: Vec<Vec<i128>>,
    /// The golden model's `RESULT_PORTS` values for ray id k at index k; None where no ray
    /// has that id.
    pub expected: Vec<Option<Vec<i128>>>,
    pub stalls: Stalls,
    /// The consumer's `res_ready` pattern and the reset clocks (`disturb::Disturb`; no
    /// scrambling in an HDL simulator).
    pub sink: Stalls,
    pub resets: Vec<u64>,
    pub max_cycles: u64,
    /// The core's ray slots (for the occupancy figure).
    pub slots: u64,
    /// With an external-memory core: the memory model's timing and the scene image it serves
    /// (at `frame_memory::SIM_BASE`).
    pub memory: Option<(crate::verify::memory::MemoryTiming, Vec<u8>)>,
}

/// The stream testbench's data for `rays` (in feed order) through the core.
pub fn frame_stream(p: &CoreParams, scene: &Scene, rays: &[PixelRay], stalls: &Stalls) -> Result<FrameStream> {
    let roms = SceneRoms::of(scene);
    let core = core_module(p, &roms);
    let id_width = p.trav.id_width;
    let max_id = rays.iter().map(|r| r.pixel as u64).max().unwrap_or(0);
    if id_width < 64 && max_id >> id_width != 0 {
        return Err(Error::new("ray id", format!("pixel {max_id} does not fit the core's {id_width}-bit ray id")));
    }
    let g = FastGolden::new(scene);
    let inputs = rays.iter().map(|r| ray_inputs(r.pixel as u64, &r.ray)[1..].to_vec()).collect();
    let mut expected = vec![None; max_id as usize + 1];
    for r in rays {
        expected[r.pixel as usize] = Some(result_row(r.pixel as u64, g.trace(&r.ray).0));
    }
    // Generous: the slowest built-in scene needs ~28,000 cycles per ray; with room for the
    // source's stalls (a period holds at most 4,055 at 99 %). Capped to what the testbenches'
    // 32-bit integers hold (GHDL would wrap it, Verilator refuses it).
    let max_cycles =
        ((100_000 + 100 * stalls.per_period() as u64) * rays.len() as u64 + 10_000).min(i32::MAX as u64 - 1);
    let (sink, resets) = (Stalls::none(), Vec::new());
    let memory = match &p.mem {
        Some(m) => Some((
            crate::verify::memory::MemoryTiming::default(),
            crate::scene::memory::SceneImage::build(&roms, m.spec.shape)?.bytes,
        )),
        None => None,
    };
    Ok(FrameStream {
        core,
        rays: inputs,
        expected,
        stalls: stalls.clone(),
        sink,
        resets,
        max_cycles,
        slots: p.slot_count() as u64,
        memory,
    })
}

/// Streams `rays` (in the order given, with `stalls`) through the core's HDL in `sim` with a
/// generated stream testbench, which checks every result by its ray id against the golden
/// model and writes what the core produced; those results (not the golden ones) are returned
/// in the order they came out.
pub fn simulate_hdl(
    sim: Simulator,
    p: &CoreParams,
    scene: &Scene,
    rays: &[PixelRay],
    stalls: &Stalls,
    dir: &Path,
) -> Result<(Vec<CoreResult>, CoreStats)> {
    if !sim.available() {
        return Err(Error::new(sim.name(), "is not installed (scripts/install-deps.sh installs it)"));
    }
    if rays.is_empty() {
        return Ok((Vec::new(), CoreStats::default()));
    }
    run_stream(sim, &frame_stream(p, scene, rays, stalls)?, dir)
}

/// Writes the stream testbench of `s` for `sim` into `dir`, runs it, and returns the results
/// it wrote (in arrival order) and its counts. A testbench that finds a mismatch fails: Err,
/// with the simulator's last lines (among them `N passed, M failed`).
pub fn run_stream(sim: Simulator, s: &FrameStream, dir: &Path) -> Result<(Vec<CoreResult>, CoreStats)> {
    let m = &s.core;
    let stall_bits = (!s.stalls.is_none()).then(|| s.stalls.period());
    let sink_bits = (!s.sink.is_none()).then(|| s.sink.period());
    let stream = Stream {
        rays: &s.rays,
        expected: &s.expected,
        checked: &RESULT_PORTS,
        id: "res_id",
        stalls: stall_bits.as_deref(),
        sink: sink_bits.as_deref(),
        resets: &s.resets,
        max_cycles: s.max_cycles,
        mem_base: s.memory.as_ref().map(|_| crate::verify::memory::SIM_BASE),
    };
    let io = |e: std::io::Error| Error::file(dir, e.to_string());
    let mut files = crate::io::OutputSet::new();
    files.extend(stream_files(m, &stream, sim).into_iter().map(|(file, text)| (dir.join(file), text)))?;
    let mut extra = Vec::new();
    if let Some((timing, image)) = &s.memory {
        let addr_bits = m.inputs.iter().find(|&&i| m.sig(i).name == "mem_base").map_or(32, |&i| m.sig(i).ty.width);
        let data_bits = m.inputs.iter().find(|&&i| m.sig(i).name == "m_axi_rdata").map_or(64, |&i| m.sig(i).ty.width);
        let base = crate::verify::memory::SIM_BASE;
        let model =
            crate::verify::memory_hdl::model_files(timing, data_bits, addr_bits, base, image, sim == Simulator::Ghdl);
        files.extend(model.into_iter().map(|(file, text)| (dir.join(file), text)))?;
        extra.push(crate::verify::memory_hdl::MODEL);
    }
    files.commit()?;
    let (_, out) = sim.run_bench_with(dir, m, Bench::Stream, &extra).map_err(|e| Error::new(sim.name(), e))?;
    let text = std::fs::read_to_string(dir.join("results.txt")).map_err(io)?;
    let rows = parse_results(m, &RESULT_PORTS, &text).map_err(|e| Error::file(&dir.join("results.txt"), e))?;
    let results = rows.iter().map(|r| core_result(r)).collect();
    // "cycles C busy B stack S" and "stalls N", wherever the simulator put them on their lines.
    let numbers = |key: &str| -> Vec<u64> {
        let line = out.lines().find_map(|l| l.find(key).map(|i| &l[i..]));
        line.unwrap_or("")
            .split_whitespace()
            .filter_map(|w| w.trim_end_matches(|c: char| !c.is_ascii_digit()).parse().ok())
            .collect()
    };
    let [cycles, busy_cycles, stack] = numbers("cycles ")[..] else {
        return Err(Error::new(sim.name(), format!("no 'cycles … busy … stack …' line in:\n{out}")));
    };
    let [stall_cycles] = numbers("stalls ")[..] else {
        return Err(Error::new(sim.name(), format!("no 'stalls …' line in:\n{out}")));
    };
    let stats = CoreStats {
        cycles,
        rays: s.rays.len() as u64,
        busy_cycles,
        max_stack_depth: stack as u32,
        slots: s.slots,
        stall_cycles,
        ..Default::default()
    };
    Ok((results, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::rtl::sim::Sim;
    use crate::scene::SceneSource;
    use crate::verify::feed::feed_order;

    fn cornell(n: u32, m: u32) -> Scene {
        Scene::load(&SceneSource::Builtin("cornell".into()), &Params { n, m, ..Params::default() }).unwrap()
    }

    /// The frame harness in both engines, output by output, clock by clock: rays in pixel
    /// order, and shuffled with the source stalling on 40 % of the cycles.
    #[test]
    fn harness_runs_alike_in_both_engines() {
        let scene = cornell(16, 16);
        let rays = frame_rays(&scene, &Camera::default_for(&scene, 6, 6));
        harness_alike(&scene, &rays, &Stalls::none());
        harness_alike(&scene, &feed_order(&rays, Some(3)), &Stalls::random(40, 2));
    }

    fn harness_alike(scene: &Scene, rays: &[PixelRay], stalls: &Stalls) {
        let roms = SceneRoms::of(scene);
        let p = CoreParams::new(&roms, 8, 1, crate::cores::clock::DEFAULT_TARGET_MHZ);
        let m = frame_harness(&p, &roms, rays, stalls);
        let outs: Vec<_> = m.outputs.iter().map(|(_, i)| m.handle(*i)).collect();
        // Every ray finishes: about 140 cycles per ray on the Cornell box at the default target
        // (docs/CORE.md), plus the pipeline and the stalls.
        let cycles = 7000;
        let mut sim = Sim::new(&m);
        let want: Vec<Vec<i128>> = (0..cycles)
            .map(|_| {
                sim.tick();
                outs.iter().map(|o| sim.get(*o)).collect()
            })
            .collect();
        let mut got = vec![vec![0i128; outs.len()]; cycles];
        BatchSim::new(&m, 64).unwrap().run(cycles, |_, _| 0, |c, k, v| got[c][k] = v);
        for c in 0..cycles {
            assert_eq!(got[c], want[c], "cycle {c}: {:?}", m.outputs.iter().map(|o| &o.0).collect::<Vec<_>>());
        }
        assert!(want.iter().filter(|r| r[0] == 1).count() == rays.len());
    }

    /// Each ray's golden result, as the core would return it.
    fn golden_results(scene: &Scene, rays: &[PixelRay]) -> Vec<CoreResult> {
        let g = FastGolden::new(scene);
        rays.iter().map(|r| (r.pixel as u64, g.trace(&r.ray).0)).collect()
    }

    /// Results are matched to rays by id: any order is right; a swapped, duplicated, missing
    /// or unknown result is one mismatch each (a duplicate also leaves its ray's own result
    /// missing).
    #[test]
    fn mismatches_match_results_to_rays_by_id() {
        let scene = cornell(29, 32);
        let rays = frame_rays(&scene, &Camera::default_for(&scene, 12, 10));
        let good = golden_results(&scene, &rays);
        assert_eq!(mismatches(&scene, &rays, &good), 0);
        // Any order.
        let mut reversed = good.clone();
        reversed.reverse();
        assert_eq!(mismatches(&scene, &rays, &reversed), 0);
        assert_eq!(mismatches(&scene, &feed_order(&rays, Some(9)), &good), 0);
        // Two rays with different results: (a, hit of b) and (b, hit of a).
        let (a, b) = (0..good.len())
            .flat_map(|a| (a + 1..good.len()).map(move |b| (a, b)))
            .find(|&(a, b)| good[a].1 != good[b].1)
            .expect("rays with different results");
        let mut swapped = good.clone();
        (swapped[a].1, swapped[b].1) = (good[b].1, good[a].1);
        assert_eq!(mismatches(&scene, &rays, &swapped), 2, "swapped hits");
        // Ray b's result twice, ray a's never: the duplicate and the missing result.
        let mut duplicated = good.clone();
        duplicated[a] = good[b];
        assert_eq!(mismatches(&scene, &rays, &duplicated), 2, "duplicate");
        let mut dup_extra = good.clone();
        dup_extra.push(good[b]);
        assert_eq!(mismatches(&scene, &rays, &dup_extra), 1, "an extra copy");
        let mut missing = good.clone();
        missing.remove(a);
        assert_eq!(mismatches(&scene, &rays, &missing), 1, "missing");
        let mut unknown = good.clone();
        unknown.push((12 * 10 + 5, None));
        assert_eq!(mismatches(&scene, &rays, &unknown), 1, "unknown id");
        let mut renamed = good.clone();
        renamed[a].0 = 12 * 10 + 5;
        assert_eq!(mismatches(&scene, &rays, &renamed), 2, "an unknown id instead of a's");
        assert_eq!(mismatches(&scene, &rays, &[]), rays.len() as u64);
    }
}
