//! The whole ray tracing core on full frames: every pixel's result (ray id, triangle, t, u, v)
//! from the generated core equals the golden model's, in the Rust simulator on every built-in
//! scene, in Verilator on a 128² frame and in GHDL on a 16² frame, which also renders the
//! binary teapot of seed 001 figure 3.7 — at two clock targets: the default (150 MHz: split
//! products, every splitting stage registered) and 75 MHz (one-clock products, the thesis-like
//! pipeline), which also keeps the two largest scenes' frames short.

mod common;

use fxrt::cores::top::CoreParams;
use fxrt::flow::feed::Stalls;
use fxrt::flow::frame::{binary_png, frame_rays, ids_image, mismatches, simulate_hdl, simulate_rust};
use fxrt::flow::simulators::Simulator;
use fxrt::model::camera::Camera;
use fxrt::params::Params;
use fxrt::render::render;
use fxrt::render::tracer::{ModelKind, make_tracer};
use fxrt::scene::images::SceneRoms;
use fxrt::scene::{Scene, SceneSource};

fn scene(name: &str) -> Scene {
    Scene::load(&SceneSource::Builtin(name.into()), &Params::default()).unwrap()
}

const DEFAULT: u32 = fxrt::cores::clock::DEFAULT_TARGET_MHZ;

/// A frame through the core built for `target_mhz`, in the Rust simulator: its ids must equal
/// `fxrt render`'s.
fn rust_frame(name: &str, size: u32, target_mhz: u32) {
    let s = scene(name);
    let roms = SceneRoms::of(&s);
    let cam = Camera::default_for(&s, size, size);
    let p = CoreParams::new(&roms, 16, 1, target_mhz);
    let rays = frame_rays(&s, &cam);
    let (results, stats) = simulate_rust(&p, &roms, &rays, &Stalls::none(), &|_| {});
    assert_eq!(mismatches(&s, &rays, &results), 0, "{name}");
    let golden = render(&s, make_tracer(&s, ModelKind::Golden).as_ref(), &cam, false, false);
    assert_eq!(ids_image(&s, size, size, &results), golden.ids, "{name}");
    assert!(stats.busy_cycles > 0, "{name}: {stats:?}");
    common::say(&format!(
        "{name} {size}² at {target_mhz} MHz: {} rays, {:.1} cycles/ray, fill {:.3}, stack {}",
        stats.rays,
        stats.cycles_per_ray(),
        stats.fill(),
        stats.max_stack_depth
    ));
}

#[test]
fn rust_teapot_128() {
    rust_frame("teapot", 128, DEFAULT);
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
fn rust_jackstraws_64() {
    // ~28,000 cycles per ray at 75 MHz (seed 001's stress test for a BIH; ~15,000 before the
    // traversal was pipelined): 64² keeps it to about 110 M clock cycles.
    rust_frame("jackstraws", 64, 75);
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
