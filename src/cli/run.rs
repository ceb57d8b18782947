//! Running each command on its validated configuration (`cli::config`). A command returns
//! Ok(false) when it ran but found a mismatch (exit 1); every error is the user's input
//! (exit 2, one line).

use super::Command;
use super::HwArgs;
use super::config::{
    BenchConfig, CompareConfig, Family, GenConfig, GenScene, RenderConfig, SceneConfig, SimConfig, Simulation,
    SynthConfig, TestConfig, ids_fit, thread_pool,
};
use super::sweep_config::{SweepConfig, SweepRun};
use crate::cores::intersect::IntersectParams;
use crate::error::Result;
use crate::fpga::{ecp5, xilinx};
use crate::generate;
use crate::io::OutputSet;
use crate::model::camera::Camera;
use crate::model::golden::Golden;
use crate::model::raygen::RayGen;
use crate::params::Params;
use crate::render::{self, tracer};
use crate::scene::images::SceneRoms;
use crate::scene::{self, Scene, SceneSource, rom};
use crate::sweep::fit::SceneSearch;
use crate::sweep::{run as sweep, slurm};
use crate::verify::{check, feed, frame, vectors};
use std::path::Path;

/// Runs `cmd`: Ok(true) when it succeeded, Ok(false) when it found a mismatch.
pub fn run(cmd: Command) -> Result<bool> {
    // A misspelt forced path is an input error, not a silent fallback (render::fast).
    crate::render::fast::GoldenPath::from_env()?;
    match cmd {
        Command::Demo(a) => super::demo::demo(&a.config()?),
        Command::Render(a) => render(&a.config()?).map(|()| true),
        Command::Scene(a) => scene(&a.config()?).map(|()| true),
        Command::Compare(a) => compare(&a.config()?).map(|()| true),
        Command::Bench(a) => bench(&a.config()?),
        Command::Gen(a) => {
            let c = a.config()?;
            match &c.board {
                Some(b) => super::board::gen_board(&c, b),
                None => gen_core(&c).map(|()| true),
            }
        }
        Command::Synth(a) => synth_cores(&a.config()?).map(|()| true),
        Command::Sweep(a) => sweep_cmd(a.config()?),
        Command::Sim(a) => sim(&a.config()?),
        Command::Test(a) => test(&a.config()?),
    }
}

pub fn render(c: &RenderConfig) -> Result<()> {
    let pool = thread_pool(c.threads)?;
    let scene = Scene::load(&c.scene, &c.params)?;
    let cam = c.camera.camera(&scene)?;
    let tracer = tracer::make_tracer(&scene, c.model);
    let frame = pool.install(|| render::render(&scene, tracer.as_ref(), &cam, c.shade, true));
    let mut files = OutputSet::new();
    if let Some(p) = &c.files.png {
        files.add(p, &frame.png_bytes())?;
    }
    if let Some(p) = &c.files.ids {
        files.add(p, &frame.ids_bytes())?;
    }
    if let Some(p) = &c.files.depth {
        files.add(p, &frame.depth_bytes())?;
    }
    files.commit()?;
    println!(
        "rays: {}, hits: {}, seconds: {:.3}, Mrays/s: {:.2}",
        frame.rays,
        frame.hits,
        frame.seconds,
        frame.rays as f64 / frame.seconds.max(1e-9) / 1e6
    );
    Ok(())
}

pub fn compare(c: &CompareConfig) -> Result<()> {
    let pool = thread_pool(c.threads)?;
    let scene = Scene::load(&c.scene, &c.params)?;
    let cam = c.camera.camera(&scene)?;
    let (g, r) = pool.install(|| {
        let golden = tracer::make_tracer(&scene, tracer::ModelKind::Golden);
        let reference = tracer::make_tracer(&scene, c.against);
        (
            render::render(&scene, golden.as_ref(), &cam, false, true),
            render::render(&scene, reference.as_ref(), &cam, false, true),
        )
    });
    let d = render::compare::compare(&g, &r);
    println!(
        "{}",
        serde_json::json!({ "scene": scene.name, "against": format!("{:?}", c.against).to_lowercase(), "edge_shift": scene.edge_shift, "disagreement": d, "rate": d.rate() })
    );
    Ok(())
}

/// The agreement property on `netlists` random netlists with a progress bar; prints
/// `N passed, N failed` and the first differences.
fn bench_agree(netlists: u64) -> bool {
    let bar = indicatif::ProgressBar::new(netlists);
    bar.set_style(
        indicatif::ProgressStyle::with_template("netlists [{bar:40}] {pos}/{len} ({eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let failures = crate::rtl::random::agree(0..netlists, &|| bar.inc(1));
    bar.finish_and_clear();
    for f in failures.iter().take(10) {
        eprintln!("{f}");
    }
    println!("agree: {} passed, {} failed", netlists - failures.len() as u64, failures.len());
    failures.is_empty()
}

/// Runs a benchmark; false when `bench agree` found a difference, or `--against-embree` hit
/// counts that disagree.
pub fn bench(c: &BenchConfig) -> Result<bool> {
    match *c {
        BenchConfig::Agree { netlists } => return Ok(bench_agree(netlists)),
        BenchConfig::Exact(ref campaign) => return super::exact::bench_exact(campaign),
        BenchConfig::AgainstEmbree { width, height, threads, repeat } => {
            return super::bench_embree::against_embree(width, height, threads, repeat);
        }
        _ => {}
    }
    let params = Params::default();
    let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &params)?;
    match *c {
        BenchConfig::Sim { vectors, ghdl_vectors } => {
            let hw = HwArgs {
                tag_width: 32,
                div_bits: 1,
                target_mhz: crate::cores::clock::DEFAULT_TARGET_MHZ,
                threads: super::ThreadArgs::DEFAULT,
            };
            let p = intersect_params(&params, &scene, &hw)?;
            let vectors = vectors::generate(&scene, vectors, 1);
            let speeds = check::bench_sims(&p, &vectors, ghdl_vectors, Path::new("target/fxrt-bench"))?;
            for s in &speeds {
                println!(
                    "{:>9}: {:>9} cycles in {:>7.3} s = {:>12.0} cycles/s{}",
                    s.simulator,
                    s.cycles,
                    s.seconds,
                    s.cycles_per_second,
                    if s.all_passed { "" } else { "  (MISMATCHES)" }
                );
            }
            let rate = |n: &str| speeds.iter().find(|s| s.simulator == n).map(|s| s.cycles_per_second);
            if let (Some(r), Some(v)) = (rate("rust"), rate("verilator")) {
                println!("rust / verilator = {:.2}", r / v);
            }
            if let (Some(r), Some(g)) = (rate("rust"), rate("ghdl")) {
                println!("rust / ghdl = {:.1}", r / g);
            }
        }
        BenchConfig::Render { width, height, threads, repeat } => {
            let pool = thread_pool(Some(threads))?;
            let cam = Camera::default_for(&scene, width, height);
            let golden = tracer::make_tracer(&scene, tracer::ModelKind::Golden);
            let (mut best, mut rays) = (f64::INFINITY, 0);
            for _ in 0..repeat {
                let f = pool.install(|| render::render(&scene, golden.as_ref(), &cam, false, false));
                best = best.min(f.seconds);
                rays = f.rays;
            }
            println!(
                "teapot {width}x{height} golden primary rays, {threads} thread(s): best of {repeat}: {best:.3} s, {:.2} Mrays/s",
                rays as f64 / best / 1e6
            );
        }
        BenchConfig::Agree { .. } | BenchConfig::AgainstEmbree { .. } | BenchConfig::Exact(_) => {
            unreachable!("answered above")
        }
    }
    Ok(true)
}

pub fn scene(c: &SceneConfig) -> Result<()> {
    let scene = Scene::load(&c.scene, &c.params)?;
    let roms = rom::words(&scene);
    let mut files = OutputSet::new();
    for (layout, words) in &roms {
        let text = rom::readmemh(layout, words);
        files.add(&c.out.join(format!("{}.hex", layout.rom)), text.as_bytes())?;
        files.add(&c.out.join(format!("{}.mem", layout.rom)), text.as_bytes())?;
        files.add(&c.out.join(format!("{}.coe", layout.rom)), rom::coe(layout, words).as_bytes())?;
    }
    files.add(&c.out.join("fxrt_scene_pkg.vhd"), rom::vhdl_package(&scene, &roms).as_bytes())?;
    let image = scene::memory::SceneImage::build(&SceneRoms::of(&scene), c.memory)?;
    files.add(&c.out.join("scene.bin"), &image.bytes)?;
    files.add(&c.out.join("fxrt_scene.h"), scene::memory_c::c_header(&scene.name, &image.layout).as_bytes())?;
    let mut json = scene::report::scene_json(&scene, &roms);
    json["memory"] = serde_json::to_value(&image.layout).unwrap_or_default();
    let json = serde_json::to_string_pretty(&json).unwrap_or_default() + "\n";
    files.add(&c.out.join("scene.json"), json.as_bytes())?;
    files.commit()?;
    if c.stats {
        print!("{}", scene::report::stats_text(&scene));
    }
    println!(
        "{}: {} triangles ({} degenerate, {} clamped), E = {}, {} BIH nodes, depth {}, memory image {} bytes ({}-bit port, {}-byte lines), written to {}",
        scene.name,
        scene.counts.stored,
        scene.counts.degenerate,
        scene.counts.clamped,
        scene.edge_shift,
        scene.bih_stats.nodes,
        scene.bih_stats.depth,
        image.layout.total_bytes,
        c.memory.mem_bits,
        c.memory.line_bytes,
        c.out.display()
    );
    Ok(())
}

/// The pipeline's widths for a parameter set and scene (E comes from the scene when auto).
fn intersect_params(params: &Params, scene: &Scene, hw: &HwArgs) -> Result<IntersectParams> {
    let (tag_width, div_bits, target_mhz) = (hw.tag_width, hw.div_bits, hw.target_mhz);
    let (n, m, t, e, piece) = (params.n, params.m, params.t, scene.edge_shift, hw.piece());
    let p = IntersectParams { n, m, t, e, tag_width, div_bits, target_mhz, piece, spread: false };
    p.check()?;
    Ok(p)
}

pub fn gen_core(c: &GenConfig) -> Result<()> {
    let (mut scene, search) = match &c.scene {
        GenScene::Folder(_) => (None, SceneSearch::default()),
        GenScene::Scene { source, params, search, .. } => (Some(Scene::load(source, params)?), *search),
    };
    let raygen = match (&c.scene, &scene) {
        (GenScene::Scene { raygen: Some(cam), .. }, Some(scene)) => Some(RayGen::for_camera(scene, cam)?),
        _ => None,
    };
    if let Some(g) = &raygen {
        ids_fit(c.ray_id_width, g.width, g.height)?;
    }
    let external = c.memory == super::args::MemoryPlace::External;
    let (spec, fit) = super::device::shape(&c.threads, scene.as_mut(), search, c.core_spec(), external)?;
    let roms = match (&c.scene, &scene) {
        (GenScene::Folder(dir), _) => SceneRoms::load(dir)?,
        (_, Some(scene)) => SceneRoms::of(scene),
        (_, None) => unreachable!("a scene is loaded unless the ROMs come from a folder"),
    };
    let p = crate::cores::top::CoreParams::shaped(&roms, &spec);
    p.check()?;
    let p = super::placement::place_checked(c.memory, c.mem_spec, c.bram_kbits, &roms, &spec, p, fit.is_some())?;
    if p.mem.is_some() && raygen.is_some() {
        return Err(crate::error::Error::param(
            "raygen",
            "not with the scene in external memory yet (--memory onchip)",
        ));
    }
    let o = generate::GenOptions {
        vhdl: c.vhdl,
        verilog: c.verilog,
        ise: c.ise,
        debug_ports: c.debug_ports,
        clock_mhz: c.target_mhz as f64,
    };
    // The core, built once: its measured report is checked against it, and its files, its
    // manifest's latency and the AXI frame's layout are made from it.
    let core = std::rc::Rc::new(crate::cores::top::core_module_with(&p, &roms, c.debug_ports));
    let measured = match c.measured.as_deref() {
        Some(f) => Some(ecp5::measured_core(f, &p, &core, &roms.name)?),
        None => None,
    };
    let mut files = OutputSet::new();
    let fit_json = fit.as_ref().map(|f| serde_json::to_value(f).expect("a fit serialises"));
    let written = generate::core_files(&p, &roms, &core, o, raygen.as_ref(), measured.as_ref(), fit_json.as_ref());
    files.extend(written.into_iter().map(|(n, t)| (c.out.join(n), t)))?;
    super::placement::add_scene_image(&mut files, &c.out, &p, &roms)?;
    if let (Some(spec), Some(scene)) = (&c.axis_frame, &scene) {
        let rays = frame::frame_rays(scene, &spec.camera(scene)?);
        ids_fit(c.ray_id_width, spec.width, spec.height)?;
        let layout = crate::cores::axis::Layout::of(&core);
        let stream = crate::generate::axis_host::frame_files(&layout, scene, &rays);
        files.extend(stream.into_iter().map(|(n, b)| (c.out.join(n), b)))?;
    }
    files.commit()?;
    println!(
        "{}_{} for {} ({} triangles{}; intersection pipeline {} cycles) written to {}",
        if raygen.is_some() { "fxrt_core_raygen" } else { "fxrt_core" },
        p.trav.scene_tag,
        roms.name,
        roms.tri_count(),
        if p.mem.is_some() { ", scene in external memory: scene.bin" } else { ", scene on chip" },
        p.isect.latency(),
        c.out.display()
    );
    super::device::say(fit.as_ref());
    Ok(())
}

pub fn test(c: &TestConfig) -> Result<bool> {
    let scene = Scene::load(&c.scene, &c.params)?;
    let p = intersect_params(&c.params, &scene, &c.hw)?;
    let vectors = vectors::generate(&scene, c.vectors, c.seed);
    let hits = vectors.iter().filter(|v| v.expected.is_some()).count();
    let start = std::time::Instant::now();
    let (outcome, unit) = match (c.sim, &c.build) {
        (Simulation::Hdl(sim), Some(dir)) => (check::run_hdl(sim, &p, &vectors, dir)?, "clock cycles"),
        _ => (check::run_rust(&p, &vectors), "vectors"),
    };
    println!(
        "{}: {} vectors ({} hits) from {}, latency {}, {} simulator, {:.1} s; counting {unit}",
        p.name(),
        vectors.len(),
        hits,
        scene.name,
        p.latency(),
        c.sim.title(),
        start.elapsed().as_secs_f64()
    );
    println!("{} passed, {} failed", outcome.passed, outcome.failed);
    Ok(outcome.failed == 0 && outcome.passed > 0)
}

pub fn synth_cores(c: &SynthConfig) -> Result<()> {
    let mut scene = Scene::load(&c.scene, &c.params)?;
    let piece = c.hw.threads.piece_or(c.family.piece());
    let p = crate::cores::intersect::IntersectParams { piece, ..intersect_params(&c.params, &scene, &c.hw)? };
    let base = crate::cores::top::CoreSpec {
        id_width: crate::cores::top::DEFAULT_RAY_ID_WIDTH,
        div_bits: c.hw.div_bits,
        target_mhz: c.hw.target_mhz,
        piece,
        ..Default::default()
    };
    let external = c.memory == super::args::MemoryPlace::External;
    let (shape, fit) = super::device::shape(&c.hw.threads, Some(&mut scene), c.search, base, external)?;
    let roms = SceneRoms::of(&scene);
    let core = crate::cores::top::CoreParams::shaped(&roms, &shape);
    core.check()?;
    let fitted = fit.is_some();
    let core = super::placement::place_checked(c.memory, c.mem_spec, c.bram_kbits, &roms, &shape, core, fitted)?;
    super::device::say(fit.as_ref());
    eprintln!(
        "synth: scene {} {}",
        scene.name,
        if core.mem.is_some() { "in external memory (AXI4 read port, caches on chip)" } else { "in on-chip ROMs" }
    );
    if let Family::Ecp5 { target_mhz, seeds, placer, modules } = &c.family {
        let tools = ecp5::Tools { placer: *placer, ..ecp5::Tools::require()? };
        return synth_ecp5(c, &tools, &p, &core, &roms, *target_mhz, seeds, modules, &scene.name);
    }
    let family = if c.family == Family::Xc7 { "xc7" } else { "xc5v" };
    let mut cores = Vec::new();
    let mut set = vec![(crate::cores::top::core_module_with(&core, &roms, false), None)];
    set.extend(generate::cores(&p).into_iter().map(|(m, lat, _)| (m, lat)));
    for (m, latency) in set {
        let area = xilinx::synth_xilinx(&m, family, &c.build.join(&m.name))?;
        cores.push(serde_json::json!({ "latency_cycles": latency, "area": area }));
    }
    let thesis = serde_json::json!({ "note": "whole design of seed 001 table 3.2 (BIH + intersection + ray generator), XST", "luts": 5278, "registers": 3274, "dsp48e": 52, "bram18": 22 });
    println!(
        "{}",
        serde_json::json!({ "family": family, "tool": "yosys synth_xilinx", "scene": scene.name, "params": p, "cores": cores, "thesis": thesis })
    );
    Ok(())
}

/// `fxrt synth --family ecp5`: each module placed and routed at every seed, one JSON
/// document (per module the median seed's figures, every seed's Fmax and the spread).
#[allow(clippy::too_many_arguments)]
fn synth_ecp5(
    c: &SynthConfig,
    tools: &ecp5::Tools,
    p: &IntersectParams,
    core: &crate::cores::top::CoreParams,
    roms: &SceneRoms,
    target_mhz: f64,
    seeds: &[u64],
    modules: &[String],
    scene: &str,
) -> Result<()> {
    let jobs = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut timings = Vec::new();
    for name in modules {
        let (m, latency) = ecp5::module_of(name, p, core, roms);
        eprintln!(
            "ecp5: placing ({}) and routing {} at seed{} {} ({} at a time; minutes for the larger modules)",
            tools.placer.name(),
            m.name,
            if seeds.len() == 1 { "" } else { "s" },
            seeds.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", "),
            jobs.min(seeds.len())
        );
        let dir = c.build.join(&m.name);
        // A spinner per seed shows its nextpnr's phase: the whole core takes hours a seed.
        let logs: Vec<_> = seeds.iter().map(|&s| (s, ecp5::seeds::seed_dir(&dir, seeds, s))).collect();
        let placed = ecp5::progress::watching(&logs, |say| {
            let seen = |t: &ecp5::Timing| say(&format!("ecp5: {} seed {}: {:.1} MHz", t.module, t.seed, t.fmax_mhz));
            ecp5::seeds::place_and_route_seeds(tools, &m, latency, target_mhz, seeds, jobs, &dir, &seen)
        })?;
        if seeds.len() > 1 {
            eprintln!(
                "ecp5: {}: median {:.1} MHz (seed {}), {:.1}–{:.1} over {} seeds",
                m.name,
                placed.median.fmax_mhz,
                placed.median.seed,
                placed.fmax_min_mhz,
                placed.fmax_max_mhz,
                seeds.len()
            );
        }
        timings.push(placed);
    }
    println!("{}", serde_json::json!({ "family": "ecp5", "scene": scene, "params": p, "modules": timings }));
    Ok(())
}

/// `fxrt sim`: a frame through the generated core; true when every pixel matched.
pub fn sim(c: &SimConfig) -> Result<bool> {
    let mut scene = Scene::load(&c.scene, &c.params)?;
    let cam = c.camera.camera(&scene)?;
    let (w, h) = (cam.width, cam.height);
    let id_width = rom::addr_bits((w * h) as usize);
    let base =
        crate::cores::top::CoreSpec { id_width, div_bits: c.div_bits, target_mhz: c.target_mhz, ..Default::default() };
    let external = c.memory == super::args::MemoryPlace::External;
    let (spec, fit) = super::device::shape(&c.threads, Some(&mut scene), c.search, base, external)?;
    let roms = SceneRoms::of(&scene);
    let p = crate::cores::top::CoreParams::shaped(&roms, &spec);
    p.check()?;
    let p = external_core(c, &roms, &spec, p, fit.is_some())?;
    super::device::say(fit.as_ref());
    let raygen = if c.raygen { Some(RayGen::for_camera(&scene, &c.camera)?) } else { None };
    let rays = match &raygen {
        Some(g) => {
            let golden = Golden::new(&scene);
            (0..w * h).map(|i| frame::PixelRay { pixel: i, ray: g.ray(&golden, i % w, i / w) }).collect()
        }
        None if c.tiles => feed::tile_order(&frame::frame_rays(&scene, &cam), |r| r.pixel, w, 8),
        // Shuffled (or not) here, once: every simulator feeds the rays in this order.
        None => feed::feed_order(&frame::frame_rays(&scene, &cam), c.shuffle_seed),
    };
    let mut memory_stats = None;
    let stalls = c.stalls.map_or_else(feed::Stalls::none, |(percent, seed)| feed::Stalls::random(percent, seed));
    let start = std::time::Instant::now();
    // `SimArgs::config` allows the ray generator in the Rust simulator only.
    let (results, stats) = match (c.sim, &c.build, &raygen) {
        (Simulation::Rust, _, Some(g)) => {
            let bar = frame::progress_bar(rays.len() as u64, "rust");
            let m = crate::cores::top::core_with_raygen(
                &p,
                &std::rc::Rc::new(crate::cores::top::core_module(&p, &roms)),
                g,
            );
            let r = frame::collect_batched(&m, rays.len(), p.slot_count(), 0, &|n| bar.set_position(n));
            bar.finish_and_clear();
            r
        }
        (Simulation::Rust, _, None) if p.mem.is_some() => {
            let image = scene::memory::SceneImage::build(&roms, c.mem_spec.shape)?;
            let bar = frame::progress_bar(rays.len() as u64, "rust");
            let run =
                crate::verify::frame_memory::simulate_external(&p, &roms, &image, &rays, c.mem_timing, &stalls, &|n| {
                    bar.set_position(n)
                });
            bar.finish_and_clear();
            // A core that stops is a defect found, as a mismatch is: one line, exit 1.
            let (results, stats, ms) = match run {
                Ok(r) => r,
                Err(stopped) => {
                    eprintln!("fxrt: {stopped}");
                    return Ok(false);
                }
            };
            memory_stats = Some(ms);
            (results, stats)
        }
        (Simulation::Hdl(sim), Some(dir), None) if p.mem.is_some() => {
            if !sim.available() {
                return Err(crate::error::Error::new(
                    sim.name(),
                    "is not installed (scripts/install-deps.sh installs it)",
                ));
            }
            // The testbench's memory model, with this run's timing.
            let mut stream = frame::frame_stream(&p, &scene, &rays, &stalls)?;
            if let Some((timing, _)) = stream.memory.as_mut() {
                *timing = c.mem_timing;
            }
            frame::run_stream(sim, &stream, dir)?
        }
        (Simulation::Hdl(sim), Some(dir), None) => frame::simulate_hdl(sim, &p, &scene, &rays, &stalls, dir)?,
        _ => {
            let bar = frame::progress_bar(rays.len() as u64, "rust");
            let r = frame::simulate_rust(&p, &roms, &rays, &stalls, &|n| bar.set_position(n));
            bar.finish_and_clear();
            r
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    let mismatches = frame::mismatches(&scene, &rays, &results);
    // Whether the results came back in the order the rays went in, and in pixel order.
    let in_order = results.len() == rays.len() && results.iter().zip(&rays).all(|(r, ray)| r.0 == ray.pixel as u64);
    let in_pixel_order = results.windows(2).all(|w| w[0].0 < w[1].0);
    let ids = frame::ids_image(&scene, w, h, &results);
    let mut files = OutputSet::new();
    if let Some(path) = &c.png {
        files.add(path, &frame::binary_png(w, h, &ids))?;
    }
    if let Some(path) = &c.ids {
        files.add(path, &ids.iter().flat_map(|i| i.to_le_bytes()).collect::<Vec<u8>>())?;
    }
    files.commit()?;
    let counted = c.sim.name() == "rust";
    // The walk: the core's node steps (counted in the Rust simulator only) and triangle tests
    // against the golden culled walk's — equal for every shape and feed order when the core
    // visits what the model specifies.
    let (golden_steps, golden_tests) = frame::golden_walk(&scene, &rays);
    let walk_matches = stats.busy_cycles == golden_tests && (!counted || stats.visits + stats.culls == golden_steps);
    let mut line = serde_json::json!({
        "scene": scene.name, "simulator": c.sim.name(), "size": format!("{w}x{h}"),
        "pixels": w * h, "rays": stats.rays, "cycles": stats.cycles,
        "cycles_per_ray": (stats.cycles_per_ray() * 100.0).round() / 100.0,
        // Per pipeline: the triangles that entered them over cycles × pipelines.
        "pipeline_fill": (stats.fill() / p.pipelines as f64 * 10000.0).round() / 10000.0,
        "max_stack_depth": stats.max_stack_depth, "mismatches": mismatches,
        "rays_per_clock": (stats.rays_per_clock() * 1e5).round() / 1e5,
        "triangle_tests_per_ray": (stats.triangle_tests_per_ray() * 100.0).round() / 100.0,
        // The HDL testbenches count neither node steps nor occupied slots (`CoreStats`): null
        // there rather than a zero that reads as measured.
        "node_steps_per_ray": counted.then(|| (stats.node_steps_per_ray() * 100.0).round() / 100.0),
        "golden_node_steps_per_ray": (golden_steps as f64 / stats.rays.max(1) as f64 * 100.0).round() / 100.0,
        "walk_matches": walk_matches,
        "slot_occupancy": counted.then(|| (stats.slot_occupancy() * 10000.0).round() / 10000.0),
        "slots": p.slot_count(), "units": p.units, "pipelines": p.pipelines,
        "all_pixels_match": mismatches == 0, "seconds": (seconds * 1000.0).round() / 1000.0,
        "shuffle_seed": c.shuffle_seed, "stall_percent": c.stalls.map_or(0, |s| s.0),
        "stall_seed": c.stalls.map(|s| s.1), "stall_cycles": stats.stall_cycles,
        "results_in_feed_order": in_order, "results_in_pixel_order": in_pixel_order,
        "memory": if p.mem.is_some() { "external" } else { "onchip" },
        "ray_order": if c.tiles { "tiles" } else { "pixels" },
    });
    let memory_fields = memory_stats.map(|ms| serde_json::to_value(&ms).unwrap_or_default());
    if let (Some(serde_json::Value::Object(fields)), Some(obj)) = (memory_fields, line.as_object_mut()) {
        obj.extend(fields);
    }
    // Hardware speed: one ray per `cycles_per_ray` clocks (one ray in flight).
    if let Some((mhz, measured)) = c.clock {
        let key = if measured { "mrays_per_s_at_fmax" } else { "mrays_per_s_at_clock" };
        line["clock_mhz"] = serde_json::json!(mhz);
        line[key] = serde_json::json!((mhz / stats.cycles_per_ray() * 1e4).round() / 1e4);
    }
    if let Some(f) = &fit {
        line["device_fit"] = serde_json::to_value(f).unwrap_or_default();
    }
    println!("{line}");
    Ok(mismatches == 0 && walk_matches)
}

/// The core `fxrt sim` runs: `p` (on chip) unless `--memory external`, or `auto` and its ROMs do
/// not fit `--bram-kbits`; an external-memory core runs with host rays.
fn external_core(
    c: &SimConfig,
    roms: &SceneRoms,
    shape: &crate::cores::top::CoreSpec,
    p: crate::cores::top::CoreParams,
    fitted: bool,
) -> Result<crate::cores::top::CoreParams> {
    let p = super::placement::place_checked(c.memory, c.mem_spec, c.bram_kbits, roms, shape, p, fitted)?;
    if p.mem.is_some() && c.raygen {
        return Err(crate::error::Error::param("memory", "an external-memory core runs with host rays (no --raygen)"));
    }
    Ok(p)
}

/// Ok(false): the simulated core disagreed with the golden model somewhere (`--core-sim`).
fn sweep_cmd(c: SweepConfig) -> Result<bool> {
    let r = match c {
        SweepConfig::Merge { dirs, out, cache } => {
            let dirs: Vec<&Path> = dirs.iter().map(|d| d.as_path()).collect();
            let rows = sweep::merge(&dirs, &out, cache.as_deref())?;
            println!("merged {} folders: {rows} configurations into {}", dirs.len(), out.display());
            return Ok(true);
        }
        SweepConfig::Run(r) => r,
    };
    let SweepRun { spec, plan, out, cache, threads, shard, slurm } = &*r;
    let pool = thread_pool(*threads)?;
    // Every scene is loaded and checked before anything is written, scripts included.
    let scenes = pool.install(|| sweep::load_scenes(spec))?;
    if let Some((shards, cpus)) = *slurm {
        slurm::emit(spec, plan.configs.len(), out, cache, shards, cpus)?;
        println!(
            "{} configurations in {} shards: submit with {}/slurm/submit.sh (Slurm) or run {}/slurm/parallel.sh (GNU parallel)",
            plan.configs.len(),
            shards,
            out.display(),
            out.display()
        );
        return Ok(true);
    }
    // Refused before the first line of output (sweep::run checks again for other callers).
    if spec.ecp5.is_some() {
        ecp5::Tools::require()?;
    }
    eprintln!(
        "sweep: {} configurations ({} parameter sets × {} scenes){}{}",
        plan.configs.len(),
        plan.sets.len(),
        spec.scenes.len(),
        shard.map(|s| format!(", shard {s}")).unwrap_or_default(),
        if plan.skipped.is_empty() { String::new() } else { format!(", {} invalid sets skipped", plan.skipped.len()) }
    );
    let start = std::time::Instant::now();
    let summary = pool.install(|| sweep::run(spec, plan, &scenes, out, cache, *shard, true))?;
    println!(
        "{} computed, {} from the cache, {} incomplete, in {:.1} s: {}",
        summary.computed,
        summary.cached,
        summary.failed,
        start.elapsed().as_secs_f64(),
        out.join("report.md").display()
    );
    if summary.mismatches > 0 {
        eprintln!("fxrt: the simulated core disagreed with the golden model on {} rays", summary.mismatches);
    }
    Ok(summary.mismatches == 0)
}
