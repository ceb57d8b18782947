//! The whole ray tracing core on full frames: every pixel's result (ray id, triangle, t, u, v)
//! from the generated core equals the golden model's, in the Rust simulator on every built-in
//! scene, in Verilator on a 128² frame and in GHDL on a 16² frame, which also renders the
//! binary teapot of seed 001 figure 3.7 — at two clock targets: the default (150 MHz: split
//! products, every splitting stage registered) and 75 MHz (one-clock products, the thesis-like
//! pipeline), which also keeps the two largest scenes' frames short. And with the rays fed
//! shuffled and the source stalling at random, in every simulator: results are matched to rays
//! by id, so a core that returns them out of order is checked the same way.

mod common;

use fxrt::cores::top::CoreParams;
use fxrt::model::camera::Camera;
use fxrt::params::Params;
use fxrt::render::render;
use fxrt::render::tracer::{ModelKind, make_tracer};
use fxrt::scene::images::SceneRoms;
use fxrt::scene::{Scene, SceneSource};
use fxrt::verify::feed::{Stalls, feed_order};
use fxrt::verify::frame::{
    CoreResult, PixelRay, binary_png, frame_rays, frame_stream, golden_walk, ids_image, mismatches, run_stream,
    simulate_hdl, simulate_rust,
};
use fxrt::verify::simulators::Simulator;
use fxrt::verify::simulators::parse_summary;

fn scene(name: &str) -> Scene {
    Scene::load(&SceneSource::Builtin(name.into()), &Params::default()).unwrap()
}

const DEFAULT: u32 = fxrt::cores::clock::DEFAULT_TARGET_MHZ;

/// A frame through the core built for `target_mhz`, in the Rust simulator: its ids must equal
/// `fxrt render`'s.
fn rust_frame(name: &str, size: u32, target_mhz: u32) {
    let shape = (Params::default().leaf_size, fxrt::cores::top::DEFAULT_SLOTS, fxrt::cores::top::DEFAULT_UNITS, 1);
    rust_frame_shaped(name, size, target_mhz, shape);
}

/// The same for a core of `slots` × `units` and `pipelines` on a tree of leaves up to
/// `leaf_size`.
fn rust_frame_shaped(name: &str, size: u32, target_mhz: u32, shape: (u32, u32, u32, u32)) {
    let (leaf_size, slots, units, pipelines) = shape;
    let s = Scene::load(&SceneSource::Builtin(name.into()), &Params { leaf_size, ..Params::default() }).unwrap();
    let roms = SceneRoms::of(&s);
    let cam = Camera::default_for(&s, size, size);
    let p = CoreParams::shaped(
        &roms,
        &fxrt::cores::top::CoreSpec {
            id_width: 16,
            div_bits: 1,
            target_mhz,
            slots,
            units,
            pipelines,
            piece: Default::default(),
        },
    );
    let rays = frame_rays(&s, &cam);
    let (results, stats) = simulate_rust(&p, &roms, &rays, &Stalls::none(), &|_| {});
    assert_eq!(mismatches(&s, &rays, &results), 0, "{name}");
    let golden = render(&s, make_tracer(&s, ModelKind::Golden).as_ref(), &cam, false, false);
    assert_eq!(ids_image(&s, size, size, &results), golden.ids, "{name}");
    assert!(stats.busy_cycles > 0, "{name}: {stats:?}");
    // The hardware's node visits, culls and triangle tests are the golden culled walk's.
    let g = fxrt::model::golden::Golden::new(&s);
    let (mut visits, mut culls, mut tests) = (0u64, 0u64, 0u64);
    for r in &rays {
        let (_, w) = g.trace_culled(&s, &r.ray);
        (visits, culls, tests) = (visits + w.nodes as u64, culls + w.culled as u64, tests + w.tri_tests as u64);
    }
    assert_eq!((stats.visits, stats.culls, stats.busy_cycles), (visits, culls, tests), "{name}");
    common::say(&format!(
        "{name} {size}² at {target_mhz} MHz: {} rays, {:.2} cycles/ray ({:.4} rays/clock), fill {:.3}, \
         {:.2} node steps and {:.2} triangle tests per ray, slots {:.3} occupied, stack {} ({units} × {slots}, \
         {pipelines} pipelines, leaves ≤ {leaf_size})",
        stats.rays,
        stats.cycles_per_ray(),
        stats.rays_per_clock(),
        stats.fill(),
        stats.node_steps_per_ray(),
        stats.triangle_tests_per_ray(),
        stats.slot_occupancy(),
        stats.max_stack_depth
    ));
}

/// Issue 27's small widths (n = 4 and 8 with m = 8 or 16, other T and C: the traversal took
/// the ray ahead's direction sign when a plane distance equalled tmin, common on a coarse
/// grid) and the widths at the ends of the ranges (m = 50: three directions no longer fit one
/// RAM word; n = 40: a pipeline tag of 70 bits), each an 8² teapot frame in the Rust
/// simulator: every result and the walk as the golden model's.
#[test]
fn rust_teapot_small_and_extreme_widths() {
    for (n, m, t, c) in
        [(4, 8, 0, 16), (4, 16, 0, 16), (8, 8, 3, 2), (8, 8, 0, 0), (4, 8, 6, 64), (20, 50, 0, 8), (40, 45, 0, 40)]
    {
        let params = Params { n, m, t, c, ..Params::default() };
        let s = Scene::load(&SceneSource::Builtin("teapot".into()), &params).unwrap();
        let roms = SceneRoms::of(&s);
        let p = CoreParams::shaped(
            &roms,
            &fxrt::cores::top::CoreSpec {
                id_width: 8,
                div_bits: 1,
                target_mhz: DEFAULT,
                slots: 64,
                units: 2,
                pipelines: 1,
                piece: Default::default(),
            },
        );
        p.check().unwrap();
        let rays = frame_rays(&s, &Camera::default_for(&s, 8, 8));
        let (results, stats) = simulate_rust(&p, &roms, &rays, &Stalls::none(), &|_| {});
        assert_eq!(mismatches(&s, &rays, &results), 0, "n {n} m {m} t {t} c {c}");
        assert_eq!((stats.visits + stats.culls, stats.busy_cycles), golden_walk(&s, &rays), "n {n} m {m} t {t} c {c}");
    }
}

#[test]
fn rust_teapot_128() {
    rust_frame("teapot", 128, DEFAULT);
}

/// The throughput build of docs/TIMING.md (four units of 32 slots, leaves of up to three
/// triangles: 10 Mrays/s on the LFE5U-85F).
#[test]
fn rust_teapot_128_four_units_leaf_3() {
    rust_frame_shaped("teapot", 128, DEFAULT, (3, 32, 4, 1));
}

/// Two intersection pipelines, each fed by two of four units of 32 slots (issue 30's shape
/// for the LFE5U-85F): every pixel, visit, cull and triangle test the golden model's.
#[test]
fn rust_teapot_128_four_units_two_pipelines() {
    rust_frame_shaped("teapot", 128, DEFAULT, (4, 32, 4, 2));
}

#[test]
fn rust_cornell_thin_random_128() {
    for name in ["cornell", "thin", "random"] {
        rust_frame(name, 128, DEFAULT);
    }
}

#[test]
fn rust_teapot_fine_128() {
    // 57,360 triangles: the 50k+ scene.
    rust_frame("teapot-fine", 128, 75);
}

#[test]
fn rust_jackstraws_32() {
    // Seed 001's stress test for a BIH: ~4,100 node steps and ~4,700 triangle tests per ray
    // (SAH tree); 32² keeps the 128-slot core's batched simulation to minutes (64² ran over
    // ten).
    rust_frame("jackstraws", 32, 75);
}

fn hdl_frame(sim: Simulator, size: u32, target_mhz: u32) -> Option<(Scene, Vec<i32>)> {
    if !sim.available() {
        common::say(&format!("skipped: {} is not installed", sim.name()));
        return None;
    }
    let s = scene("teapot");
    let roms = SceneRoms::of(&s);
    let cam = Camera::default_for(&s, size, size);
    let p = CoreParams::new(&roms, 16, 1, target_mhz);
    let rays = frame_rays(&s, &cam);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("frame_{}", sim.name()));
    let (results, stats) = simulate_hdl(sim, &p, &s, &rays, &Stalls::none(), &dir).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(mismatches(&s, &rays, &results), 0);
    // The HDL's cycle count and statistics equal the Rust simulator's.
    let (_, rust) = simulate_rust(&p, &roms, &rays, &Stalls::none(), &|_| {});
    assert_eq!(
        (stats.cycles, stats.busy_cycles, stats.max_stack_depth),
        (rust.cycles, rust.busy_cycles, rust.max_stack_depth)
    );
    Some((s, ids_image(&scene("teapot"), size, size, &results)))
}

#[test]
fn verilator_teapot_128() {
    hdl_frame(Simulator::Verilator, 128, DEFAULT);
}

#[test]
fn ghdl_teapot_16_renders_the_binary_teapot() {
    let Some((_, ids)) = hdl_frame(Simulator::Ghdl, 16, 75) else { return };
    let hits = ids.iter().filter(|&&i| i >= 0).count();
    assert!(hits > 40 && hits < 200, "{hits} of 256 pixels hit");
    let png = binary_png(16, 16, &ids);
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("ghdl_teapot_16.png");
    std::fs::write(&path, &png).unwrap();
    let decoder = png::Decoder::new(std::io::Cursor::new(png));
    let info = decoder.read_info().unwrap().info().clone();
    assert_eq!((info.width, info.height), (16, 16));
}

/// Whether results came back in an order other than the pixels' (the ids not ascending).
fn out_of_pixel_order(results: &[CoreResult]) -> bool {
    results.windows(2).any(|w| w[0].0 > w[1].0)
}

/// Shuffled rays and a source that stalls on 30 % of the cycles, in the Rust simulator: every
/// pixel as `fxrt render` has it, the results really came back out of pixel order, and the
/// stalls really cost cycles.
#[test]
fn rust_frames_shuffled_and_stalled() {
    for (name, size) in [("teapot", 32), ("cornell", 24)] {
        let s = scene(name);
        let roms = SceneRoms::of(&s);
        let cam = Camera::default_for(&s, size, size);
        let p = CoreParams::new(&roms, 16, 1, DEFAULT);
        let pixel_order = frame_rays(&s, &cam);
        let rays = feed_order(&pixel_order, Some(42));
        let stalls = Stalls::random(30, 7);
        let (results, stats) = simulate_rust(&p, &roms, &rays, &stalls, &|_| {});
        // Matched by id: against the rays in pixel order, not in the order they went in.
        assert_eq!(mismatches(&s, &pixel_order, &results), 0, "{name}");
        let golden = render(&s, make_tracer(&s, ModelKind::Golden).as_ref(), &cam, false, false);
        assert_eq!(ids_image(&s, size, size, &results), golden.ids, "{name}");
        assert!(out_of_pixel_order(&results), "{name}: the rays were not shuffled");
        let (_, unstalled) = simulate_rust(&p, &roms, &rays, &Stalls::none(), &|_| {});
        // The stalls happened (whether they cost cycles depends on whether the source or the
        // core is the bottleneck: with every ray slot busy, a stalled ray was waiting anyway).
        assert!(stats.stall_cycles > 0 && unstalled.stall_cycles == 0, "{name}: {stats:?}");
        common::say(&format!(
            "{name} {size}² shuffled, 30 % stalls: {} cycles ({} without stalls), {} stall cycles",
            stats.cycles, unstalled.cycles, stats.stall_cycles
        ));
    }
}

/// A tiny teapot frame — its rays in pixel order, and shuffled — with stalls, and the core
/// built for 75 MHz (short).
fn tiny_shuffled() -> (fxrt::scene::Scene, CoreParams, Vec<PixelRay>, Vec<PixelRay>, Stalls) {
    let s = scene("teapot");
    let roms = SceneRoms::of(&s);
    let p = CoreParams::new(&roms, 8, 1, 75);
    let pixel_order = frame_rays(&s, &Camera::default_for(&s, 8, 8));
    let rays = feed_order(&pixel_order, Some(3));
    (s, p, pixel_order, rays, Stalls::random(35, 9))
}

/// The HDL stream testbenches with shuffled rays and a stalling source: they pass, their
/// results come in the same order as the Rust simulator's and their counts — stall cycles
/// too — are the same, so every simulator saw the same stream, cycle for cycle. Then a core
/// of four units and two intersection pipelines, in three of the simulators.
#[test]
fn hdl_frames_shuffled_and_stalled() {
    let (s, p, pixel_order, rays, stalls) = tiny_shuffled();
    let all = [Simulator::Iverilog, Simulator::IverilogSv, Simulator::Ghdl, Simulator::Verilator];
    let mut failures = shuffled_and_stalled_in(&all, "", &s, &p, (&pixel_order, &rays), &stalls);
    let shape = fxrt::cores::top::CoreSpec {
        id_width: 8,
        target_mhz: 75,
        slots: 4,
        units: 4,
        pipelines: 2,
        ..Default::default()
    };
    let two = CoreParams::shaped(&SceneRoms::of(&s), &shape);
    let some = [Simulator::IverilogSv, Simulator::Ghdl, Simulator::Verilator];
    failures.extend(shuffled_and_stalled_in(&some, "two_pipelines_", &s, &two, (&pixel_order, &rays), &stalls));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The frame `rays` (`pixel_order` the same rays in pixel order) through core `p` in each of
/// `sims` (`label` names their folders) against the Rust simulator: the failures.
fn shuffled_and_stalled_in(
    sims: &[Simulator],
    label: &str,
    s: &Scene,
    p: &CoreParams,
    (pixel_order, rays): (&[PixelRay], &[PixelRay]),
    stalls: &Stalls,
) -> Vec<String> {
    let (rust, rust_stats) = simulate_rust(p, &SceneRoms::of(s), rays, stalls, &|_| {});
    assert!(out_of_pixel_order(&rust) && rust_stats.stall_cycles > 0);
    assert_eq!(mismatches(s, pixel_order, &rust), 0, "{label}");
    let check = |sim: Simulator| -> Result<(), String> {
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("shuffled_{label}{}", sim.name()));
        let (results, stats) = simulate_hdl(sim, p, s, rays, stalls, &dir).map_err(|e| e.to_string())?;
        let bad = mismatches(s, pixel_order, &results);
        let counts = |c: &fxrt::verify::frame::CoreStats| (c.cycles, c.busy_cycles, c.max_stack_depth, c.stall_cycles);
        match () {
            _ if bad != 0 => Err(format!("{bad} mismatches")),
            _ if results != rust => Err("results not in the Rust simulator's arrival order".into()),
            _ if counts(&stats) != counts(&rust_stats) => {
                Err(format!("counts {:?}, Rust {:?}", counts(&stats), counts(&rust_stats)))
            }
            _ => Ok(()),
        }
    };
    each_simulator(sims, check)
}

/// The HDL stream testbenches with a consumer ready on 40 % of the clocks and three one-clock
/// resets in the frame's first pass: every simulator passes (every ray after the last reset
/// one right result, every result before it right), with the Rust cycle simulator's results,
/// in its order, and its counts — the same stream, cycle for cycle.
#[test]
fn hdl_frames_with_a_slow_consumer_and_resets() {
    use fxrt::verify::disturb::{Disturb, simulate_cycle};
    let (s, p, pixel_order, rays, stalls) = tiny_shuffled();
    let d = Disturb { sink: Stalls::random(60, 4), resets: vec![37, 160, 409], scramble: None };
    let rust = simulate_cycle(&p, &SceneRoms::of(&s), &rays, &stalls, &d, &|_| {});
    assert_eq!(mismatches(&s, &pixel_order, &rust.results), 0);
    assert!(!rust.before_reset.is_empty(), "a reset came after results");
    let mut fs = frame_stream(&p, &s, &rays, &stalls).unwrap();
    (fs.sink, fs.resets) = (d.sink.clone(), d.resets.clone());
    let check = |sim: Simulator| -> Result<(), String> {
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("disturbed_{}", sim.name()));
        let (results, stats) = run_stream(sim, &fs, &dir).map_err(|e| e.to_string())?;
        let counts = |c: &fxrt::verify::frame::CoreStats| (c.cycles, c.busy_cycles, c.max_stack_depth, c.stall_cycles);
        match () {
            _ if results != rust.results => Err("results not the Rust simulator's, in its order".into()),
            _ if counts(&stats) != counts(&rust.stats) => {
                Err(format!("counts {:?}, Rust {:?}", counts(&stats), counts(&rust.stats)))
            }
            _ => Ok(()),
        }
    };
    let failures =
        each_simulator(&[Simulator::Iverilog, Simulator::IverilogSv, Simulator::Ghdl, Simulator::Verilator], check);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `check` in every simulator that is installed (the others are skipped, said so): each
/// simulator's failure, named.
fn each_simulator(sims: &[Simulator], check: impl Fn(Simulator) -> Result<(), String>) -> Vec<String> {
    let mut failures = Vec::new();
    for &sim in sims {
        if !sim.available() {
            common::say(&format!("skipped: {} is not installed", sim.name()));
            continue;
        }
        if let Err(e) = check(sim) {
            failures.push(format!("{}: {e}", sim.name()));
        }
    }
    failures
}

/// The stream testbench catches what it must, whatever the order: a wrong expected value, a
/// result whose id no ray has, a second result for an id and an id left without a result —
/// each one failure, named in its output.
#[test]
fn hdl_testbench_fails_on_corrupted_entries() {
    let (s, p, _, rays, stalls) = tiny_shuffled();
    let n = rays.len() as u64;
    let mut fs = frame_stream(&p, &s, &rays, &stalls).unwrap();
    let [x, y, a, b] = [0, 1, 2, 3].map(|k| rays[k].pixel as usize);
    // x's expected v is off by one.
    fs.expected[x].as_mut().unwrap()[5] ^= 1;
    // y is no ray's id any more.
    fs.expected[y] = None;
    // Ray b is replaced by a copy of ray a: a second result for a (whichever comes second),
    // none for b.
    fs.rays[3] = fs.rays[2].clone();
    let check = |sim: Simulator| -> Result<(), String> {
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("corrupted_{}", sim.name()));
        let Err(err) = run_stream(sim, &fs, &dir) else { return Err("the testbench passed".into()) };
        let err = err.message;
        if parse_summary(&err) != Some((n - 3, 4)) {
            return Err(format!("not {} passed, 4 failed: {err}", n - 3));
        }
        let lines = [
            format!("ray id {x} differs"),
            format!("no ray has id {y}"),
            format!("a second result for ray id {a}"),
            format!("ray id {b}: no result"),
        ];
        match lines.iter().find(|l| !err.contains(l.as_str())) {
            Some(l) => Err(format!("no '{l}' in {err}")),
            None => Ok(()),
        }
    };
    let failures = each_simulator(&[Simulator::Iverilog, Simulator::Ghdl], check);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
