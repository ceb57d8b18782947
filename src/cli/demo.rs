//! `fxrt` with no arguments (and `fxrt demo`): the whole product on the embedded teapot, in one
//! folder and under a minute. The core is generated in both languages (with its ROM images and
//! manifest), a frame runs through that same netlist in the Rust simulator, every pixel is
//! checked against the golden model, and both pictures are written: the golden model's, shaded,
//! and the one the hardware's hits make.

use crate::cores::memory_params::MemorySpec;
use crate::cores::top::{CoreParams, core_module_with};
use crate::error::{Error, Result};
use crate::generate;
use crate::io::OutputSet;
use crate::model::camera::Camera;
use crate::params::Params;
use crate::render::{self, Frame, tracer::GoldenTracer};
use crate::scene::images::SceneRoms;
use crate::scene::memory::SceneImage;
use crate::scene::{Scene, SceneSource};
use crate::verify::frame_memory::simulate_external;
use crate::verify::memory::MemoryTiming;
use crate::verify::{feed, frame};
use std::path::{Path, PathBuf};

use super::args_hw::DemoArgs;

/// The ray id width of `fxrt gen`'s default, so the simulated core is the generated one.
const RAY_ID_WIDTH: u32 = 20;
/// The default build's place-and-route report (scripts/measure-default.sh): its clock is the
/// demo core's when it measured this very netlist.
const MEASURED: &str = include_str!("../../generated/measured/ecp5-core.json");
/// The golden model's picture: larger than the simulated frame, it costs a fraction of a second.
const PICTURE: u32 = 512;

/// What `demo` is asked for.
#[derive(Debug, Clone)]
pub struct DemoConfig {
    pub out: PathBuf,
    /// The simulated frame.
    pub width: u32,
    pub height: u32,
    pub memory: super::args::MemoryPlace,
    pub device: Option<crate::fpga::device::Device>,
}

impl DemoArgs {
    pub fn config(&self) -> crate::error::Result<DemoConfig> {
        let (width, height) = self.size;
        check_size(width, height)?;
        crate::io::check_folder(&self.out)?;
        Ok(DemoConfig { out: self.out.clone(), width, height, memory: self.memory, device: self.device })
    }
}

/// Runs the demo; Ok(false) when a pixel of the simulated core differs from the golden model.
pub fn demo(c: &DemoConfig) -> Result<bool> {
    let mut scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default())?;
    let target = crate::cores::clock::DEFAULT_TARGET_MHZ;
    let base = crate::cores::top::CoreSpec { id_width: RAY_ID_WIDTH, target_mhz: target, ..Default::default() };
    let threads = super::ThreadArgs { device: c.device, ..super::ThreadArgs::DEFAULT };
    let external = c.memory == super::args::MemoryPlace::External;
    let search = crate::sweep::fit::SceneSearch::ALL;
    let (shape, fit) = super::device::shape(&threads, Some(&mut scene), search, base, external)?;
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::shaped(&roms, &shape);
    p.check()?;
    // The demo runs on the ULX3S's LFE5U-85F.
    let bram_kbits = crate::fpga::device::Device::Lfe5u85f.bram_kbits();
    let (spec, fitted) = (MemorySpec::default(), fit.is_some());
    let p = super::placement::place_checked(c.memory, spec, bram_kbits, &roms, &shape, p, fitted)?;
    super::config::ids_fit(RAY_ID_WIDTH, c.width, c.height)?;
    super::device::say(fit.as_ref());
    let fit_json = fit.as_ref().map(|f| serde_json::to_value(f).unwrap_or_default());
    let netlist = std::rc::Rc::new(core_module_with(&p, &roms, false));
    let measured = crate::fpga::ecp5::measured_entry(
        Path::new("generated/measured/ecp5-core.json"),
        MEASURED,
        &p,
        &netlist,
        &roms.name,
    )
    .ok();
    let o =
        generate::GenOptions { vhdl: true, verilog: true, ise: false, debug_ports: false, clock_mhz: target as f64 };
    let hdl = c.out.join("hdl");
    // Kept in memory while the frame is simulated (an interrupted demo leaves nothing), then
    // written with the pictures as one set.
    let core_files = generate::core_files(&p, &roms, &netlist, o, None, measured.as_ref(), fit_json.as_ref());
    let hdl_files = core_files.len();

    // A frame through the core, in the Rust simulator, every pixel against the golden model.
    let cam = Camera::default_for(&scene, c.width, c.height);
    let rays = frame::frame_rays(&scene, &cam);
    let bar = frame::progress_bar(rays.len() as u64, "rust");
    let stalls = feed::Stalls::none();
    let (results, stats, memory) = match &p.mem {
        Some(m) => {
            let image = SceneImage::build(&roms, m.spec.shape)?;
            let timing = MemoryTiming::default();
            match simulate_external(&p, &roms, &image, &rays, timing, &stalls, &|n| bar.set_position(n)) {
                Ok((r, s, ms)) => (r, s, Some(ms)),
                Err(stopped) => {
                    bar.finish_and_clear();
                    eprintln!("fxrt: {stopped}");
                    return Ok(false);
                }
            }
        }
        None => {
            let (r, s) = frame::simulate_rust(&p, &roms, &rays, &stalls, &|n| bar.set_position(n));
            (r, s, None)
        }
    };
    bar.finish_and_clear();
    let mismatches = frame::mismatches(&scene, &rays, &results);
    let ids = frame::ids_image(&scene, c.width, c.height, &results);

    let golden = GoldenTracer::new(&scene);
    let picture = render::render(&scene, &golden, &Camera::default_for(&scene, PICTURE, PICTURE), true, false);
    let (golden_png, hardware_png) = (c.out.join("golden.png"), c.out.join("hardware.png"));
    let mut files = OutputSet::new();
    files.extend(core_files.into_iter().map(|(n, t)| (hdl.join(n), t)))?;
    super::placement::add_scene_image(&mut files, &hdl, &p, &roms)?;
    files.add(&golden_png, &picture.png_bytes())?;
    files.add(&hardware_png, &hardware_picture(&scene, &cam, ids).png_bytes())?;
    files.commit()?;

    let core = format!("fxrt_core_{}", p.trav.scene_tag);
    let pixels = (c.width * c.height) as u64;
    println!(
        "fxrt: the embedded teapot ({} triangles) as a ray tracing core, checked in the Rust simulator",
        roms.tri_count()
    );
    let scene_files = match &p.mem {
        Some(_) => "the scene image scene.bin for its external memory, fxrt_scene.h",
        None => "its ROM images",
    };
    println!(
        "  wrote {}: {} files, {core} in VHDL-93 and Verilog-2001 with {scene_files} and manifest {core}.json",
        hdl.display(),
        hdl_files + if p.mem.is_some() { 2 } else { 0 },
    );
    println!(
        "  frame {}x{}: {} rays reached the scene box, {:.2} clock cycles per ray ({:.3} rays per clock, {} units × {} slots{})",
        c.width,
        c.height,
        stats.rays,
        stats.cycles_per_ray(),
        stats.rays_per_clock(),
        p.units,
        p.slot_count() / p.units.max(1),
        if p.pipelines > 1 { format!(", {} intersection pipelines", p.pipelines) } else { String::new() }
    );
    if let (Some(ms), Some(m)) = (&memory, &p.mem) {
        println!(
            "  external memory (L = {} clocks, {}-bit port, {} KB node caches, {} KB triangle cache): {:.1} bytes per \
             ray, node cache hits {:.1} %, triangle cache hits {:.1} %",
            ms.latency,
            ms.mem_bits,
            m.spec.node_cache_kb,
            m.spec.tri_cache_kb,
            ms.figures.mem_bytes_per_ray,
            100.0 * ms.figures.node_cache_hit_rate,
            100.0 * ms.figures.tri_cache_hit_rate
        );
    }
    if mismatches == 0 {
        println!("  every pixel matched the golden model ({pixels} of {pixels})");
    } else {
        println!("  MISMATCH: {mismatches} of {pixels} pixels differ from the golden model");
    }
    match measured.as_ref().and_then(|m| m["fmax_mhz"].as_f64().map(|f| (f, m))) {
        Some((fmax, m)) => println!(
            "  clock: {fmax:.1} MHz placed and routed on the {} (nextpnr, {}): {:.1} Mrays/s",
            m["device"].as_str().unwrap_or("ECP5"),
            seeds_said(m),
            fmax * stats.rays_per_clock()
        ),
        None => println!("  clock: not measured for this netlist (scripts/measure-default.sh places and routes it)"),
    }
    println!(
        "  pictures: {} (golden model, shaded, {PICTURE}x{PICTURE}), {} (the core's hits)",
        golden_png.display(),
        hardware_png.display()
    );
    println!("next:");
    for (cmd, what) in [
        ("fxrt sim --builtin teapot --sim ghdl --size 24x24", "the same check in GHDL (or --sim verilator)"),
        ("fxrt gen --builtin cornell --out cornell/", "a core for another scene (or: fxrt gen yours.obj --out yours/)"),
        (
            "fxrt synth --family ecp5 --modules core --builtin teapot > core.json",
            "its clock and area, placed and routed",
        ),
        ("fxrt bench --against-embree", "the golden model against Embree on this CPU"),
    ] {
        println!("  {cmd:<68} # {what}");
    }
    Ok(mismatches == 0)
}

/// The core's hits as a picture: each hit pixel shaded by how squarely its ray meets the
/// triangle the core returned (as `render` without shadows), misses dark.
fn hardware_picture(scene: &Scene, cam: &Camera, ids: Vec<i32>) -> Frame {
    let (pixel_rays, normals) = (cam.pixel_rays(), render::world_normals(scene));
    let shade = ids
        .iter()
        .enumerate()
        .map(|(i, &id)| match usize::try_from(id).ok().and_then(|id| normals.get(id)) {
            Some(&n) => render::headlight(n, pixel_rays.ray(i as u32 % cam.width, i as u32 / cam.width).d) as f32,
            None => -1.0,
        })
        .collect();
    let hits = ids.iter().filter(|&&i| i >= 0).count() as u64;
    Frame { width: cam.width, height: cam.height, ids, depth: vec![], shade, rays: 0, hits, seconds: 0.0 }
}

/// `--size` of the demo frame: at most 256 × 256 (the Rust simulator's pace keeps the demo short).
pub fn check_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 || width > 256 || height > 256 {
        return Err(Error::param("size", format!("{width}x{height}: the demo frame is 1x1 to 256x256")));
    }
    Ok(())
}

/// The placement seeds of a measured report as the demo says them: "seed 1", or "median of
/// seeds 1, 2, 3: 119.3–129.6 MHz".
fn seeds_said(m: &serde_json::Value) -> String {
    let seeds: Vec<String> =
        m["seeds"].as_array().map_or(Vec::new(), |s| s.iter().map(|x| x["seed"].to_string()).collect());
    match (&seeds[..], m["fmax_min_mhz"].as_f64(), m["fmax_max_mhz"].as_f64()) {
        ([_, _, ..], Some(lo), Some(hi)) => format!("median of seeds {}: {lo:.1}–{hi:.1} MHz", seeds.join(", ")),
        _ => format!("seed {}", m["seed"]),
    }
}
