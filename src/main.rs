use clap::Parser;
use fxrt::cli::{
    BenchArgs, Cli, Command, CompareArgs, FrameSim, GenArgs, Lang, RenderArgs, SceneArgs, SimArgs, SimChoice,
    SweepAction, SweepArgs, SynthArgs, TestArgs,
};
use fxrt::cores::intersect::IntersectParams;
use fxrt::error::{Error, Result};
use fxrt::flow::simulators::Simulator;
use fxrt::render::{self, tracer};
use fxrt::scene::{self, Scene, rom};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) if matches!(e.kind(), clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion) => {
            e.exit()
        }
        Err(e) => {
            // One line, like every other input error; `--help` has the details.
            let text = e.render().to_string();
            let first = text.lines().next().unwrap_or("invalid arguments").trim_start_matches("error: ");
            eprintln!("fxrt: {first}");
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Some(Command::Render(a)) => run_render(a),
        Some(Command::Scene(a)) => run_scene(a),
        Some(Command::Compare(a)) => run_compare(a),
        Some(Command::Bench(a)) => run_bench(a),
        Some(Command::Gen(a)) => run_gen(a),
        Some(Command::Synth(a)) => run_synth(a),
        Some(Command::Sweep(a)) => match run_sweep(a) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::from(1),
            Err(e) => Err(e),
        },
        Some(Command::Sim(a)) => match run_sim(a) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::from(1),
            Err(e) => Err(e),
        },
        Some(Command::Test(a)) => match run_test(a) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::from(1),
            Err(e) => Err(e),
        },
        None => {
            // The main job on the embedded default: render the teapot to teapot.png.
            let a = Cli::parse_from(["fxrt", "render", "--png", "teapot.png", "--shade", "--size", "512x512"]);
            match a.command {
                Some(Command::Render(a)) => run_render(a),
                _ => unreachable!("the default command is a render"),
            }
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fxrt: {e}");
            ExitCode::from(2)
        }
    }
}

fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        if n == 0 || n > 1024 {
            return Err(Error::param("threads", format!("{n} is out of range: must be 1..=1024")));
        }
        b = b.num_threads(n);
    }
    b.build().map_err(|e| Error::param("threads", e.to_string()))
}

fn run_render(a: RenderArgs) -> Result<()> {
    let params = a.params.params()?;
    let pool = thread_pool(a.threads)?;
    let scene = Scene::load(&a.scene.source(), &params)?;
    let cam = a.camera.camera(&scene)?;
    let tracer = tracer::make_tracer(&scene, a.model);
    let frame = pool.install(|| render::render(&scene, tracer.as_ref(), &cam, a.shade, true));
    // Everything is computed before the first file is written.
    let mut files = Vec::new();
    if let Some(p) = &a.png {
        files.push((p.clone(), frame.png_bytes()));
    }
    if let Some(p) = &a.ids {
        files.push((p.clone(), frame.ids_bytes()));
    }
    if let Some(p) = &a.depth {
        files.push((p.clone(), frame.depth_bytes()));
    }
    fxrt::io::write_all_atomic(&files)?;
    println!(
        "rays: {}, hits: {}, seconds: {:.3}, Mrays/s: {:.2}",
        frame.rays,
        frame.hits,
        frame.seconds,
        frame.rays as f64 / frame.seconds.max(1e-9) / 1e6
    );
    Ok(())
}

fn run_compare(a: CompareArgs) -> Result<()> {
    let params = a.params.params()?;
    let pool = thread_pool(a.threads)?;
    let scene = Scene::load(&a.scene.source(), &params)?;
    let cam = a.camera.camera(&scene)?;
    let (g, r) = pool.install(|| {
        let golden = tracer::make_tracer(&scene, tracer::ModelKind::Golden);
        let reference = tracer::make_tracer(&scene, a.against);
        (
            render::render(&scene, golden.as_ref(), &cam, false, true),
            render::render(&scene, reference.as_ref(), &cam, false, true),
        )
    });
    let d = render::compare::compare(&g, &r);
    println!(
        "{}",
        serde_json::json!({ "scene": scene.name, "against": format!("{:?}", a.against).to_lowercase(), "edge_shift": scene.edge_shift, "disagreement": d, "rate": d.rate() })
    );
    Ok(())
}

fn run_bench(a: BenchArgs) -> Result<()> {
    if a.what == fxrt::cli::BenchWhat::Sim {
        let params = fxrt::params::Params::default();
        let scene = Scene::load(&scene::SceneSource::Builtin("teapot".into()), &params)?;
        let p = intersect_params(&params, &scene, &fxrt::cli::HwArgs { tag_width: 32, div_bits: 1 })?;
        let vectors = fxrt::flow::vectors::generate(&scene, a.vectors.max(1), 1);
        let speeds =
            fxrt::flow::check::bench_sims(&p, &vectors, a.ghdl_vectors, std::path::Path::new("target/fxrt-bench"))?;
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
        return Ok(());
    }
    let pool = thread_pool(Some(a.threads))?;
    let scene = Scene::load(&scene::SceneSource::Builtin("teapot".into()), &fxrt::params::Params::default())?;
    let cam = fxrt::model::camera::Camera::default_for(&scene, a.size.0, a.size.1);
    let golden = tracer::make_tracer(&scene, tracer::ModelKind::Golden);
    let mut best = f64::INFINITY;
    let mut rays = 0;
    for _ in 0..a.repeat.max(1) {
        let f = pool.install(|| render::render(&scene, golden.as_ref(), &cam, false, false));
        best = best.min(f.seconds);
        rays = f.rays;
    }
    println!(
        "teapot {}x{} golden primary rays, {} thread(s): best of {}: {:.3} s, {:.2} Mrays/s",
        a.size.0,
        a.size.1,
        a.threads,
        a.repeat.max(1),
        best,
        rays as f64 / best / 1e6
    );
    Ok(())
}

fn run_scene(a: SceneArgs) -> Result<()> {
    let params = a.params.params()?;
    let scene = Scene::load(&a.scene.source(), &params)?;
    let roms = rom::words(&scene);
    let mut files = Vec::new();
    for (layout, words) in &roms {
        let text = rom::readmemh(layout, words);
        files.push((a.out.join(format!("{}.hex", layout.rom)), text.clone().into_bytes()));
        files.push((a.out.join(format!("{}.mem", layout.rom)), text.into_bytes()));
        files.push((a.out.join(format!("{}.coe", layout.rom)), rom::coe(layout, words).into_bytes()));
    }
    files.push((a.out.join("fxrt_scene_pkg.vhd"), rom::vhdl_package(&scene, &roms).into_bytes()));
    let json = scene::report::scene_json(&scene, &roms);
    files.push((
        a.out.join("scene.json"),
        (serde_json::to_string_pretty(&json).unwrap_or_default() + "\n").into_bytes(),
    ));
    fxrt::io::write_all_atomic(&files)?;
    if a.stats {
        print!("{}", scene::report::stats_text(&scene));
    }
    println!(
        "{}: {} triangles ({} degenerate, {} clamped), E = {}, {} BIH nodes, depth {}, written to {}",
        scene.name,
        scene.counts.stored,
        scene.counts.degenerate,
        scene.counts.clamped,
        scene.edge_shift,
        scene.bih_stats.nodes,
        scene.bih_stats.depth,
        a.out.display()
    );
    Ok(())
}

/// The pipeline's widths for a parameter set and scene (E comes from the scene when auto).
fn intersect_params(params: &fxrt::params::Params, scene: &Scene, hw: &fxrt::cli::HwArgs) -> Result<IntersectParams> {
    let p = IntersectParams {
        n: params.n,
        m: params.m,
        t: params.t,
        e: scene.edge_shift,
        tag_width: hw.tag_width,
        div_bits: hw.div_bits,
    };
    p.check()?;
    Ok(p)
}

fn run_gen(a: GenArgs) -> Result<()> {
    let (roms, raygen) = match &a.scene_dir {
        Some(_) if a.raygen => {
            return Err(Error::param("raygen", "needs the scene itself (an OBJ or --builtin), not --scene DIR"));
        }
        Some(dir) => (fxrt::scene::images::SceneRoms::load(dir)?, None),
        None => {
            let scene = Scene::load(&a.scene.source(), &a.params.params()?)?;
            let raygen = if a.raygen { Some(ray_generator(&scene, &a.camera)?) } else { None };
            (fxrt::scene::images::SceneRoms::of(&scene), raygen)
        }
    };
    if !(1..=64).contains(&a.ray_id_width) {
        return Err(Error::param("ray-id-width", format!("{} is out of range: must be 1..=64", a.ray_id_width)));
    }
    if !(a.clock_mhz > 0.0 && a.clock_mhz <= 1000.0) {
        return Err(Error::param("clock-mhz", format!("{} is out of range: must be in (0, 1000]", a.clock_mhz)));
    }
    if let Some(g) = &raygen {
        let pixels = g.width as u64 * g.height as u64;
        if a.ray_id_width < 64 && pixels > 1u64 << a.ray_id_width {
            return Err(Error::param(
                "ray-id-width",
                format!("{} bits cannot number the {pixels} pixels of --size", a.ray_id_width),
            ));
        }
    }
    let p = fxrt::cores::top::CoreParams::new(&roms, a.ray_id_width, a.div_bits);
    p.check()?;
    p.check_device(&roms, a.bram_kbits)?;
    let o = fxrt::flow::generate::GenOptions {
        vhdl: a.lang.contains(&Lang::Vhdl),
        verilog: a.lang.contains(&Lang::Verilog),
        ise: a.ise,
        clock_mhz: a.clock_mhz,
    };
    let files: Vec<(std::path::PathBuf, Vec<u8>)> = fxrt::flow::generate::core_files(&p, &roms, o, raygen.as_ref())
        .into_iter()
        .map(|(n, t)| (a.out.join(n), t.into_bytes()))
        .collect();
    fxrt::io::write_all_atomic(&files)?;
    println!(
        "{} for {} ({} triangles; intersection pipeline {} cycles) written to {}",
        if raygen.is_some() { "fxrt_core_raygen" } else { "fxrt_core" },
        roms.name,
        roms.tri_count(),
        p.isect.latency(),
        a.out.display()
    );
    Ok(())
}

fn run_test(a: TestArgs) -> Result<bool> {
    let params = a.params.params()?;
    let scene = Scene::load(&a.scene.source(), &params)?;
    let p = intersect_params(&params, &scene, &a.hw)?;
    let count = a.vectors.unwrap_or(match a.sim {
        SimChoice::Rust | SimChoice::Verilator => 100_000,
        SimChoice::Iverilog => 20_000,
        SimChoice::Ghdl => 2_000,
    });
    if count == 0 {
        return Err(Error::param("vectors", "0: nothing would run"));
    }
    let vectors = fxrt::flow::vectors::generate(&scene, count, a.seed);
    let hits = vectors.iter().filter(|v| v.expected.is_some()).count();
    let start = std::time::Instant::now();
    let (outcome, unit) = match a.sim {
        SimChoice::Rust => (fxrt::flow::check::run_rust(&p, &vectors), "vectors"),
        hdl => {
            let sim = match hdl {
                SimChoice::Ghdl => Simulator::Ghdl,
                SimChoice::Iverilog => Simulator::Iverilog,
                _ => Simulator::Verilator,
            };
            let dir = a.build.clone().unwrap_or_else(|| std::path::PathBuf::from("target/fxrt-test").join(sim.name()));
            (fxrt::flow::check::run_hdl(sim, &p, &vectors, &dir)?, "clock cycles")
        }
    };
    println!(
        "{}: {} vectors ({} hits) from {}, latency {}, {:?} simulator, {:.1} s; counting {unit}",
        p.name(),
        vectors.len(),
        hits,
        scene.name,
        p.latency(),
        a.sim,
        start.elapsed().as_secs_f64()
    );
    println!("{} passed, {} failed", outcome.passed, outcome.failed);
    Ok(outcome.failed == 0 && outcome.passed > 0)
}

fn run_synth(a: SynthArgs) -> Result<()> {
    if a.family != "xc5v" {
        return Err(Error::param("family", format!("'{}' is not supported: only xc5v (Virtex-5)", a.family)));
    }
    let params = a.params.params()?;
    let scene = Scene::load(&a.scene.source(), &params)?;
    let p = intersect_params(&params, &scene, &a.hw)?;
    let roms = fxrt::scene::images::SceneRoms::of(&scene);
    let core = fxrt::cores::top::CoreParams::new(&roms, 20, a.hw.div_bits);
    core.check()?;
    let build = a.build.clone().unwrap_or_else(|| std::path::PathBuf::from("target/fxrt-synth"));
    let mut cores = Vec::new();
    let mut set = vec![(fxrt::cores::top::core_module(&core, &roms), None)];
    set.extend(fxrt::flow::generate::cores(&p).into_iter().map(|(m, lat, _)| (m, lat)));
    for (m, latency) in set {
        let area = fxrt::flow::synth::synth_xc5v(&m, &build.join(&m.name))?;
        cores.push(serde_json::json!({ "latency_cycles": latency, "area": area }));
    }
    let thesis = serde_json::json!({ "note": "whole design of seed 001 table 3.2 (BIH + intersection + ray generator), XST", "luts": 5278, "registers": 3274, "dsp48e": 52, "bram18": 22 });
    println!(
        "{}",
        serde_json::json!({ "family": "xc5v", "tool": "yosys synth_xilinx", "scene": scene.name, "params": p, "cores": cores, "thesis": thesis })
    );
    Ok(())
}

/// `fxrt sim`: a frame through the generated core; true when every pixel matched.
fn run_sim(a: SimArgs) -> Result<bool> {
    use fxrt::flow::frame;
    let params = a.params.params()?;
    let scene = Scene::load(&a.scene.source(), &params)?;
    let cam = a.camera.camera(&scene)?;
    let (w, h) = (cam.width, cam.height);
    let id_width = rom::addr_bits((w * h) as usize);
    let roms = fxrt::scene::images::SceneRoms::of(&scene);
    let p = fxrt::cores::top::CoreParams::new(&roms, id_width, a.div_bits);
    p.check()?;
    let raygen = if a.raygen { Some(ray_generator(&scene, &a.camera)?) } else { None };
    let rays = match &raygen {
        Some(g) => {
            let golden = fxrt::model::golden::Golden::new(&scene);
            (0..w * h).map(|i| frame::PixelRay { pixel: i, ray: g.ray(&golden, i % w, i / w) }).collect()
        }
        None => frame::frame_rays(&scene, &cam),
    };
    let start = std::time::Instant::now();
    let (results, stats) = match (a.sim, &raygen) {
        (FrameSim::Rust, Some(g)) => {
            let bar = frame::progress_bar(rays.len() as u64, "rust");
            let m = fxrt::cores::top::core_with_raygen(&p, &roms, g);
            let r = frame::collect_batched(&m, rays.len(), 0, &|n| bar.set_position(n));
            bar.finish_and_clear();
            r
        }
        (_, Some(_)) => return Err(Error::param("raygen", "runs in the Rust simulator only (--sim rust)")),
        (FrameSim::Rust, None) => {
            let bar = frame::progress_bar(rays.len() as u64, "rust");
            let r = frame::simulate_rust(&p, &roms, &rays, &|n| bar.set_position(n));
            bar.finish_and_clear();
            r
        }
        (hdl, None) => {
            let sim = if hdl == FrameSim::Ghdl { Simulator::Ghdl } else { Simulator::Verilator };
            let dir = a.build.clone().unwrap_or_else(|| std::path::PathBuf::from("target/fxrt-sim").join(sim.name()));
            fxrt::flow::frame::simulate_hdl(sim, &p, &scene, &rays, &dir)?
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    let mismatches = frame::mismatches(&scene, &rays, &results);
    let ids = frame::ids_image(&scene, w, h, &results);
    let mut files = Vec::new();
    if let Some(path) = &a.png {
        files.push((path.clone(), frame::binary_png(w, h, &ids)));
    }
    if let Some(path) = &a.ids {
        files.push((path.clone(), ids.iter().flat_map(|i| i.to_le_bytes()).collect()));
    }
    fxrt::io::write_all_atomic(&files)?;
    println!(
        "{}",
        serde_json::json!({
            "scene": scene.name, "simulator": format!("{:?}", a.sim).to_lowercase(), "size": format!("{w}x{h}"),
            "pixels": w * h, "rays": stats.rays, "cycles": stats.cycles,
            "cycles_per_ray": (stats.cycles_per_ray() * 100.0).round() / 100.0,
            "pipeline_fill": (stats.fill() * 10000.0).round() / 10000.0,
            "max_stack_depth": stats.max_stack_depth, "mismatches": mismatches,
            "state_cycles": stats.named_state_cycles().into_iter().map(|(n, c)| (n.to_string(), serde_json::json!(c))).collect::<serde_json::Map<String, serde_json::Value>>(),
            "all_pixels_match": mismatches == 0, "seconds": (seconds * 1000.0).round() / 1000.0,
        })
    );
    Ok(mismatches == 0)
}

/// The on-chip ray generator for a camera (inside the scene box).
fn ray_generator(scene: &Scene, camera: &fxrt::cli::CameraArgs) -> Result<fxrt::model::raygen::RayGen> {
    let cam = camera.camera(scene)?;
    fxrt::model::raygen::RayGen::new(scene, &cam).map_err(|(opt, msg)| Error::param(opt, msg))
}

/// Ok(false): the simulated core disagreed with the golden model somewhere (`--core-sim`).
fn run_sweep(a: SweepArgs) -> Result<bool> {
    use fxrt::flow::sweep::{report, run};
    if let Some(SweepAction::Merge(m)) = &a.action {
        let dirs: Vec<&std::path::Path> = m.dirs.iter().map(|d| d.as_path()).collect();
        let rows = run::merge(&dirs, &m.out, m.cache.as_deref())?;
        println!("merged {} folders: {rows} configurations into {}", dirs.len(), m.out.display());
        return Ok(true);
    }
    let spec = a.spec()?;
    let plan = spec.plan()?;
    let out = a.out.clone().expect("clap requires --out without a subcommand");
    let pool = thread_pool(a.threads)?;
    // Every scene is loaded and checked before anything is written, scripts included.
    let scenes = pool.install(|| run::load_scenes(&spec))?;
    if a.emit_slurm {
        if a.shard.is_some() {
            return Err(Error::param("emit-slurm", "writes the scripts for every shard: leave out --shard"));
        }
        let most = plan.configs.len().min(1000);
        if a.shards == 0 || a.shards as usize > most {
            return Err(Error::param(
                "shards",
                format!("{} is out of range: must be 1..={most} (configurations, and Slurm's array limit)", a.shards),
            ));
        }
        let abs = |p: &std::path::Path| std::path::absolute(p).map_err(|e| Error::file(p, e.to_string()));
        let exe = std::env::current_exe().map_err(|e| Error::new("fxrt", format!("cannot find its own path: {e}")))?;
        let cpus = a.threads.unwrap_or(4) as u32;
        let cache = a.cache.clone().unwrap_or_else(|| out.join("cache"));
        let files = report::slurm_files(&exe, &spec, &abs(&out)?, &abs(&cache)?, a.shards, cpus)?;
        for (name, text, executable) in &files {
            let path = out.join("slurm").join(name);
            fxrt::io::write_atomic(&path, text.as_bytes())?;
            #[cfg(unix)]
            if *executable {
                use std::os::unix::fs::PermissionsExt;
                let _ = std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755));
            }
        }
        println!(
            "{} configurations in {} shards: submit with {}/slurm/submit.sh (Slurm) or run {}/slurm/parallel.sh (GNU parallel)",
            plan.configs.len(),
            a.shards,
            out.display(),
            out.display()
        );
        return Ok(true);
    }
    eprintln!(
        "sweep: {} configurations ({} parameter sets × {} scenes){}{}",
        plan.configs.len(),
        plan.sets.len(),
        spec.scenes.len(),
        a.shard.map(|s| format!(", shard {s}")).unwrap_or_default(),
        if plan.skipped.is_empty() { String::new() } else { format!(", {} invalid sets skipped", plan.skipped.len()) }
    );
    let start = std::time::Instant::now();
    let cache = a.cache.clone().unwrap_or_else(|| out.join("cache"));
    let summary = pool.install(|| run::run(&spec, &plan, &scenes, &out, &cache, a.shard, true))?;
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
