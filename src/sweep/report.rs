//! report.md (the findings, the Pareto front, the plots and grids, every row), and the Slurm /
//! GNU parallel scripts of `--emit-slurm`. Both are askama templates in `hdl/`.

use super::eval::{OTHER_SURFACE_REL, Row};
use super::output::{Results, list};
use super::plots::{FMAX_PLOTS, MEMORY_PLOTS};
use super::summary::{SetSummary, cheapest_same_image, pareto_front, set_summaries};
use super::throughput::THROUGHPUT_PLOTS;
use super::{Axis, Plan, Set};
use crate::error::{Error, Result};
use crate::fpga::ecp5::{CriticalPath, DEVICE, PACKAGE, SPEED, Timing};
use crate::io::OutputSet;
use askama::Template;
use std::path::Path;

#[derive(Template)]
#[template(path = "sweep_report.md", escape = "none")]
struct Report {
    title: String,
    version: String,
    width: u32,
    height: u32,
    other_surface: f64,
    dsp_source: &'static str,
    scenes: String,
    mode: &'static str,
    lists: Vec<(&'static str, String)>,
    configurations: usize,
    sets: usize,
    scene_count: usize,
    findings: Vec<String>,
    pareto: Vec<[String; 7]>,
    plots: Vec<String>,
    grids: Vec<String>,
    /// The header of the table of all configurations.
    head: Vec<String>,
    rows: Vec<Vec<String>>,
    skipped: Vec<String>,
    ecp5_setup: String,
    ecp5_rows: Vec<Vec<String>>,
    fmax_plots: Vec<String>,
    throughput_plots: Vec<String>,
    memory_plots: Vec<String>,
    area_source: String,
}

fn findings(results: &Results, sets: &[SetSummary]) -> Vec<String> {
    let mut out = Vec::new();
    let spec = &results.spec;
    let set_text = |s: &Set| spec.set_text(s);
    let defaults = Set { params: spec.defaults(), shape: spec.base().shape };
    let default_set = sets.iter().find(|s| s.set() == defaults);
    match cheapest_same_image(sets) {
        Some(s) => out.push(format!(
            "Fewest DSP48E with the same image as the defaults on every scene: {} — {} DSP48E and {} register \
             bits{}, pipeline latency {}.",
            set_text(&s.set()),
            s.dsp48e,
            s.register_bits,
            default_set.map(|d| format!(" (defaults: {} and {})", d.dsp48e, d.register_bits)).unwrap_or_default(),
            s.isect_latency
        )),
        None => out.push("No swept parameter set gives the defaults' image on every scene.".into()),
    }
    for r in results.rows.iter().filter(|r| r.set() == defaults) {
        if let Some(q) = &r.quality {
            out.push(format!(
                "{} at the defaults: {} wrong pixels of {} ({} false misses, {} false hits, {} other surface).",
                r.scene, q.wrong_pixels, q.rays, q.false_misses, q.false_hits, q.other_surface
            ));
        }
    }
    if let Some(worst) = sets.iter().max_by_key(|s| (s.wrong, std::cmp::Reverse(s.dsp48e))) {
        out.push(format!(
            "Most wrong pixels: {} — {} of {} rays ({:.3} %).",
            set_text(&worst.set()),
            worst.wrong,
            worst.rays,
            100.0 * worst.wrong as f64 / worst.rays.max(1) as f64
        ));
    }
    let runs: Vec<&super::eval::CoreRun> = results.rows.iter().filter_map(|r| r.core.as_ref()).collect();
    if !runs.is_empty() {
        let bad: u64 = runs.iter().map(|k| k.mismatches).sum();
        let cpr = |f: fn(f64, f64) -> f64, init: f64| runs.iter().map(|k| k.cycles_per_ray).fold(init, f);
        out.push(format!(
            "The whole core ran {} configurations' frames in the Rust simulator: {} rays disagreed with the \
             golden model; {:.1} to {:.1} cycles per ray.",
            runs.len(),
            bad,
            cpr(f64::min, f64::INFINITY),
            cpr(f64::max, 0.0)
        ));
    }
    out.extend(super::throughput::finding(results));
    out.extend(pnr_findings(results));
    let failed = results.rows.iter().filter(|r| r.error.is_some()).count();
    if failed > 0 {
        out.push(format!("{failed} configurations could not be evaluated completely; see the note column."));
    }
    out
}

/// The parameter columns of the table of all configurations beyond n, m, E, T, C: the leaf
/// size when it is swept, K and U when they are not the defaults.
fn extra_axes(results: &Results) -> Vec<Axis> {
    let spec = &results.spec;
    let mut v = Vec::new();
    if spec.leaf_size.len() > 1 {
        v.push(Axis::LeafSize);
    }
    if !spec.default_core_shape() {
        v.extend([Axis::Slots, Axis::Units]);
    }
    v.extend(Axis::MEMORY.into_iter().filter(|&a| spec.values(a).len() > 1));
    v
}

fn table_head(results: &Results) -> Vec<String> {
    let mut head: Vec<String> = ["scene", "n", "m", "E (used)", "T", "C"].map(String::from).to_vec();
    head.extend(extra_axes(results).iter().map(|a| a.symbol().to_string()));
    head.extend(
        [
            "wrong px",
            "false miss",
            "false hit",
            "other surface",
            "differ",
            "max rel. t error",
            "degenerate",
            "clamped",
            "DSP48E",
            "register bits",
            "latency",
            "cycles/ray",
        ]
        .map(String::from),
    );
    if results.spec.core_sim {
        head.push("rays/clock".into());
    }
    if results.spec.core_sim && results.spec.memory.is_some() {
        head.extend(["bytes/ray", "node hits", "tri hits"].map(String::from));
    }
    head.push("note".into());
    head
}

fn row_cells(results: &Results, r: &super::eval::Row) -> Vec<String> {
    let p = &r.params;
    let e = match r.e_used {
        Some(e) if p.edge_shift.to_string() == "auto" => format!("auto ({e})"),
        _ => p.edge_shift.to_string(),
    };
    let mut v = vec![r.scene.clone(), p.n.to_string(), p.m.to_string(), e, p.t.to_string(), p.c.to_string()];
    v.extend(extra_axes(results).iter().map(|a| a.value(&r.set())));
    match &r.quality {
        Some(q) => v.extend([
            q.wrong_pixels.to_string(),
            q.false_misses.to_string(),
            q.false_hits.to_string(),
            q.other_surface.to_string(),
            q.diff_vs_default.to_string(),
            format!("{:.2e}", q.t_rel_max),
            q.triangles.degenerate.to_string(),
            q.triangles.clamped.to_string(),
        ]),
        None => v.extend(std::iter::repeat_n(String::new(), 8)),
    }
    v.push(r.dsp48e(r.synth.is_some()).map(|d| d.to_string()).unwrap_or_default());
    v.push(r.cost.as_ref().map(|c| c.register_bits.to_string()).unwrap_or_default());
    v.push(r.cost.as_ref().map(|c| c.isect_latency.to_string()).unwrap_or_default());
    v.push(r.core.as_ref().map(|k| format!("{:.1}", k.cycles_per_ray)).unwrap_or_default());
    if results.spec.core_sim {
        v.push(r.core.as_ref().map(|k| format!("{:.4}", k.rays_per_clock)).unwrap_or_default());
    }
    if results.spec.core_sim && results.spec.memory.is_some() {
        let m = r.memory.as_ref();
        v.push(m.map(|m| format!("{:.1}", m.figures.mem_bytes_per_ray)).unwrap_or_default());
        v.push(m.map(|m| format!("{:.3}", m.figures.node_cache_hit_rate)).unwrap_or_default());
        v.push(m.map(|m| format!("{:.3}", m.figures.tri_cache_hit_rate)).unwrap_or_default());
    }
    v.push(r.error.clone().unwrap_or_default().replace('|', "/"));
    v
}

/// The table of the lists: n, m, E, T, C, then the leaf size when swept and K and U when not
/// the defaults, and the base set.
fn lists(results: &Results, plan: &Plan) -> Vec<(&'static str, String)> {
    let spec = &results.spec;
    let mut v = vec![
        ("n", list(&spec.n)),
        ("m", list(&spec.m)),
        ("E (edge shift)", list(&spec.edge_shift)),
        ("T", list(&spec.t)),
        ("C", list(&spec.c)),
    ];
    if spec.leaf_size.len() > 1 {
        v.push(("leaf size", list(&spec.leaf_size)));
    }
    if !spec.default_core_shape() {
        v.push(("K (ray slots per unit)", list(&spec.slots)));
        v.push(("U (traversal units)", list(&spec.units)));
        v.push(("P (intersection pipelines)", spec.pipelines.to_string()));
    }
    if let Some(device) = spec.fitted_device() {
        let name = device.name();
        v.push((
            "shape",
            format!("fitted to the {name} on the first scene at the base set (results.json: spec.device_fit)"),
        ));
    }
    if let Some(m) = &spec.memory {
        let order = if m.tiles { "8 × 8 tiles" } else { "pixel order" };
        v.push((
            "memory",
            format!(
                "external: {}-bit AXI4 read port, {}-byte lines, {}-way caches, rays in {order}",
                m.mem_bits, m.cache_line, m.ways
            ),
        ));
        v.push(("L (memory latency, clocks)", list(&m.latency)));
        v.push(("node cache KB (each unit's)", list(&m.node_cache_kb)));
        v.push(("triangle cache KB", list(&m.tri_cache_kb)));
    }
    v.push(("base set", spec.set_text(&plan.base)));
    v
}

/// Stages report.md.
pub fn add_report(
    files: &mut OutputSet,
    dir: &Path,
    results: &Results,
    plan: &Plan,
    grids: &[String],
    plots: &[String],
) -> Result<()> {
    let spec = &results.spec;
    let sets = set_summaries(results);
    let pareto = pareto_front(&sets)
        .into_iter()
        .map(|i| {
            let s = &sets[i];
            [
                spec.set_text(&s.set()),
                s.dsp48e.to_string(),
                s.wrong.to_string(),
                s.diff.to_string(),
                s.isect_latency.to_string(),
                s.register_bits.to_string(),
                s.rom_bits.to_string(),
            ]
        })
        .collect();
    let labels = super::scene_labels(&spec.scenes);
    let report = Report {
        title: labels.join(", "),
        version: results.fxrt.clone(),
        width: spec.camera.width,
        height: spec.camera.height,
        other_surface: OTHER_SURFACE_REL,
        dsp_source: if spec.xc5v_synth() {
            "yosys synth_xilinx -family xc5v"
        } else {
            "estimated from the multipliers"
        },
        scenes: labels.join(", "),
        mode: if spec.one_at_a_time { "one parameter at a time around the base set" } else { "cross product" },
        lists: lists(results, plan),
        configurations: results.rows.len(),
        sets: plan.sets.len(),
        scene_count: spec.scenes.len(),
        findings: findings(results, &sets),
        pareto,
        plots: plots
            .iter()
            .filter(|p| ![FMAX_PLOTS, THROUGHPUT_PLOTS, MEMORY_PLOTS].iter().any(|k| p.starts_with(k)))
            .cloned()
            .collect(),
        grids: grids.to_vec(),
        head: table_head(results),
        rows: results.rows.iter().map(|r| row_cells(results, r)).collect(),
        skipped: plan.skipped.iter().map(|s| format!("{}: {}", spec.params_text(&s.params), s.reason)).collect(),
        ecp5_setup: pnr_setup_text(results),
        ecp5_rows: pnr_report_rows(results),
        fmax_plots: plots.iter().filter(|p| p.starts_with(FMAX_PLOTS)).cloned().collect(),
        throughput_plots: plots.iter().filter(|p| p.starts_with(THROUGHPUT_PLOTS)).cloned().collect(),
        memory_plots: plots.iter().filter(|p| p.starts_with(MEMORY_PLOTS)).cloned().collect(),
        area_source: super::throughput::source_text(results),
    };
    let text = report.render().map_err(|e| Error::new("sweep report", e.to_string()))?;
    files.add(&dir.join("report.md"), text.as_bytes())
}

/// The P&R setup, for the report: device, target, seed and the tools' versions.
fn pnr_setup_text(results: &Results) -> String {
    let Some(e) = &results.spec.ecp5 else { return String::new() };
    let first = results.rows.iter().flat_map(|r| r.ecp5.first()).next();
    let tools = first.map(|p| format!("; {}; {}", p.timing.yosys, p.timing.nextpnr)).unwrap_or_default();
    format!(
        "{DEVICE} ({PACKAGE}, speed grade {SPEED}), clock target {} MHz, {} ray slots × {} traversal units, \
         placement seed {}, modules {}{tools}",
        results.spec.target_mhz,
        list(&results.spec.slots),
        list(&results.spec.units),
        e.seed,
        e.modules.join(", ")
    )
}
/// A line per placed module of every row: scene, parameters, module, Fmax, resources,
/// latency, critical path, and the row's Mrays/s at Fmax on the line of the module it is
/// clocked by.
fn pnr_report_rows(results: &Results) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for r in &results.rows {
        let clock = super::pnr::clock(&r.ecp5);
        let mut marked = false;
        for p in &r.ecp5 {
            let t = &p.timing;
            let by_this = !marked && Some(t.fmax_mhz) == clock;
            marked |= by_this;
            let path = &t.critical_path;
            out.push(vec![
                r.scene.clone(),
                results.spec.set_text(&r.set()),
                p.kind.clone(),
                format!("{:.1}", t.fmax_mhz),
                t.lut4.to_string(),
                format!("{} ({})", t.ff, t.wrapper_ff),
                t.mult18.to_string(),
                t.dp16kd.to_string(),
                t.latency_cycles.map(|l| l.to_string()).unwrap_or_else(|| "–".into()),
                path_text(path),
                r.mrays_per_s_at_fmax.filter(|_| by_this).map(|x| format!("{x:.3}")).unwrap_or_default(),
            ]);
        }
    }
    out
}
/// A critical path for the report: start → end and its delay, marked when both ends are the
/// wrapper's (pins, XOR tree): the module itself is then at least this fast.
fn path_text(p: &CriticalPath) -> String {
    let ours = |cell: &str| cell.starts_with("u_dut");
    let wrapper = if !ours(&p.start) && !ours(&p.end) { " (the wrapper's)" } else { "" };
    format!("`{}` → `{}`, {:.2} ns{wrapper}", p.start, p.end, p.delay_ns).replace('|', "/")
}
/// Findings: per module, the range of Fmax over the sweep and where its slowest
/// configuration's critical path runs; the range of Mrays/s at Fmax.
fn pnr_findings(results: &Results) -> Vec<String> {
    let Some(e) = &results.spec.ecp5 else { return Vec::new() };
    let mut out = Vec::new();
    for kind in &e.modules {
        let placed: Vec<(&Row, &Timing)> = results
            .rows
            .iter()
            .filter_map(|r| r.ecp5.iter().find(|p| &p.kind == kind).map(|p| (r, &p.timing)))
            .collect();
        let by_fmax = |a: &&(&Row, &Timing), b: &&(&Row, &Timing)| a.1.fmax_mhz.total_cmp(&b.1.fmax_mhz);
        let (Some(lo), Some(hi)) = (placed.iter().min_by(by_fmax), placed.iter().max_by(by_fmax)) else { continue };
        out.push(format!(
            "ECP5 {kind}: Fmax {:.1} to {:.1} MHz over {} configurations at a {} MHz target; the slowest ({} {}): {}.",
            lo.1.fmax_mhz,
            hi.1.fmax_mhz,
            placed.len(),
            results.spec.target_mhz,
            lo.0.scene,
            super::set_label(&lo.0.set()),
            path_text(&lo.1.critical_path)
        ));
    }
    let rates: Vec<f64> = results.rows.iter().filter_map(|r| r.mrays_per_s_at_fmax).collect();
    if let (Some(lo), Some(hi)) = (rates.iter().copied().reduce(f64::min), rates.iter().copied().reduce(f64::max)) {
        let clock = if e.modules.iter().any(|m| m == "core") {
            "the whole core's Fmax"
        } else {
            "the slowest placed module's Fmax, an upper bound: place `core` for the core's own"
        };
        out.push(format!(
            "At Fmax, with one ray in flight: {lo:.3} to {hi:.3} Mrays/s ({clock} ÷ cycles per ray of the simulated core)."
        ));
    }
    out
}
