//! Whole frames through the generated core (`fxrt sim`): every pixel's ray that reaches the
//! scene box is streamed into the core in pixel order; the results come back in the same
//! order and are compared with the golden model's `trace_fast`, pixel by pixel.

use crate::cores::top::{CoreParams, core_inputs, core_module, ray_inputs};
use crate::error::{Error, Result};
use crate::flow::simulators::{Bench, Simulator};
use crate::flow::testbench::{Stream, parse_results, stream_files};
use std::path::Path;
use crate::model::golden::{Golden, GridRay, Hit};
use crate::model::ray::quantize_ray;
use crate::render::camera::Camera;
use crate::rtl::Module;
use crate::rtl::sim::Sim;
use crate::scene::Scene;
use crate::scene::images::SceneRoms;
use serde::Serialize;

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
}

impl CoreStats {
    pub fn cycles_per_ray(&self) -> f64 {
        self.cycles as f64 / self.rays.max(1) as f64
    }
    pub fn fill(&self) -> f64 {
        self.busy_cycles as f64 / self.cycles.max(1) as f64
    }
}

fn port(m: &Module, name: &str) -> crate::rtl::Sig {
    let id = m.outputs.iter().find(|o| o.0 == name).map(|o| o.1);
    let id = id.or_else(|| m.inputs.iter().copied().find(|&i| m.sig(i).name == name));
    m.handle(id.unwrap_or_else(|| panic!("{}: no port {name}", m.name)))
}

/// Streams `rays` through the core in the Rust cycle simulator. `progress` is called with the
/// number of results so far, now and then.
pub fn simulate_rust(
    p: &CoreParams,
    scene: &SceneRoms,
    rays: &[PixelRay],
    progress: &dyn Fn(u64),
) -> (Vec<CoreResult>, CoreStats) {
    let m = core_module(p, scene);
    let mut sim = Sim::new(&m);
    let ins: Vec<_> = core_inputs(p).iter().map(|(name, _)| port(&m, name)).collect();
    let [ready, busy, depth] = ["ray_ready", "busy", "stack_depth"].map(|n| port(&m, n));
    let res: Vec<_> = ["res_valid", "res_id", "res_hit", "res_tri", "res_t", "res_u", "res_v"].iter().map(|n| port(&m, n)).collect();
    let mut stats = CoreStats { rays: rays.len() as u64, ..Default::default() };
    let mut results = Vec::with_capacity(rays.len());
    let mut next = 0;
    let idle = vec![0i128; ins.len()];
    while results.len() < rays.len() {
        let values = rays.get(next).map(|r| ray_inputs(r.pixel as u64, &r.ray));
        for (s, v) in ins.iter().zip(values.as_deref().unwrap_or(&idle)) {
            sim.set(*s, *v);
        }
        sim.eval();
        let fire = values.is_some() && sim.get(ready) == 1;
        sim.tick();
        stats.cycles += 1;
        // Observed after the edge, as the testbenches do (Verilator's timing mode does not
        // show these before it).
        stats.busy_cycles += sim.get(busy) as u64;
        stats.max_stack_depth = stats.max_stack_depth.max(sim.get(depth) as u32);
        next += fire as usize;
        if sim.get(res[0]) == 1 {
            let hit = (sim.get(res[2]) == 1).then(|| Hit {
                tri: sim.get(res[3]) as u32,
                t: sim.get(res[4]) as i64,
                u: sim.get(res[5]) as i64,
                v: sim.get(res[6]) as i64,
            });
            results.push((sim.get(res[1]) as u64, hit));
            if results.len() % 256 == 0 {
                progress(results.len() as u64);
            }
        }
        assert!(stats.cycles < 1 << 40, "the core stopped producing results");
    }
    (results, stats)
}

/// Pixels whose core result differs from the golden model (id, triangle, t, u, v), and rays
/// whose result is missing or out of order.
pub fn mismatches(scene: &Scene, rays: &[PixelRay], results: &[CoreResult]) -> u64 {
    let g = Golden::new(scene);
    let mut bad = (rays.len() as u64).abs_diff(results.len() as u64);
    for (r, (id, hit)) in rays.iter().zip(results) {
        let want = g.trace_fast(scene, &r.ray).0;
        if *id != r.pixel as u64 || *hit != want {
            bad += 1;
        }
    }
    bad
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

/// A result as the values of `RESULT_PORTS`.
fn result_row(id: u64, hit: Option<Hit>) -> Vec<i128> {
    match hit {
        Some(h) => vec![id as i128, 1, h.tri as i128, h.t as i128, h.u as i128, h.v as i128],
        None => vec![id as i128, 0, 0, 0, 0, 0],
    }
}

/// Streams `rays` through the core's HDL in `sim` with a generated stream testbench, which
/// checks every result against the golden model and writes what the core produced; those
/// results (not the golden ones) are returned.
pub fn simulate_hdl(
    sim: Simulator,
    p: &CoreParams,
    scene: &Scene,
    rays: &[PixelRay],
    dir: &Path,
) -> Result<(Vec<CoreResult>, CoreStats)> {
    let roms = SceneRoms::of(scene);
    if !sim.available() {
        return Err(Error::new(sim.name(), "is not installed (scripts/install-deps.sh installs it)"));
    }
    if rays.is_empty() {
        return Ok((Vec::new(), CoreStats::default()));
    }
    let m = core_module(p, &roms);
    let g = Golden::new(scene);
    let inputs: Vec<Vec<i128>> = rays.iter().map(|r| ray_inputs(r.pixel as u64, &r.ray)[1..].to_vec()).collect();
    let expected: Vec<Vec<i128>> =
        rays.iter().map(|r| result_row(r.pixel as u64, g.trace_fast(scene, &r.ray).0)).collect();
    // Generous: the slowest built-in scene needs ~15,000 cycles per ray.
    let max_cycles = 100_000 * rays.len() as u64 + 10_000;
    let stream = Stream { rays: &inputs, expected: &expected, checked: &RESULT_PORTS, max_cycles };
    let io = |e: std::io::Error| Error::file(dir, e.to_string());
    std::fs::create_dir_all(dir).map_err(io)?;
    for (file, text) in stream_files(&m, &stream, sim) {
        std::fs::write(dir.join(file), text).map_err(io)?;
    }
    let (_, out) = sim.run_bench(dir, &m, Bench::Stream).map_err(|e| Error::new(sim.name(), e))?;
    let text = std::fs::read_to_string(dir.join("results.txt")).map_err(io)?;
    let rows = parse_results(&m, &RESULT_PORTS, &text).map_err(|e| Error::file(&dir.join("results.txt"), e))?;
    let results = rows
        .iter()
        .map(|r| {
            let hit = (r[1] == 1).then(|| Hit { tri: r[2] as u32, t: r[3] as i64, u: r[4] as i64, v: r[5] as i64 });
            (r[0] as u64, hit)
        })
        .collect();
    // "cycles C busy B stack S", wherever the simulator put it on its line.
    let stats_line = out.lines().find_map(|l| l.find("cycles ").map(|i| &l[i..]));
    let nums: Vec<u64> = stats_line
        .unwrap_or("")
        .split_whitespace()
        .filter_map(|w| w.trim_end_matches(|c: char| !c.is_ascii_digit()).parse().ok())
        .collect();
    let [cycles, busy_cycles, stack] = nums[..] else {
        return Err(Error::new(sim.name(), format!("no 'cycles … busy … stack …' line in:\n{out}")));
    };
    let stats = CoreStats { cycles, rays: rays.len() as u64, busy_cycles, max_stack_depth: stack as u32 };
    Ok((results, stats))
}
