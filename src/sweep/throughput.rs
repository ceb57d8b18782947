//! With `--core-sim`: throughput against area, a point per configuration labelled K×U (and
//! the leaf size where it is swept), a colour per scene: plots/throughput_AREA.png per area
//! measure. The area is the placed core's MULT18 and LUT4 with `--synth --family ecp5`
//! (`core` among the modules; then a second panel shows Mrays/s at Fmax), else yosys's
//! Virtex-5 DSP48E and LUTs with `--synth`, else the estimated DSP48E and register bits.

use super::draw::{FONT, H, W, draw_legend, plot_err};
use super::eval::Row;
use super::output::Results;
use super::output::list;
use crate::error::Result;
use crate::io::OutputSet;
use crate::render::encode_png;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Where the throughput plots go: plots/throughput_AREA.png.
pub const THROUGHPUT_PLOTS: &str = "plots/throughput_";

/// An area measure of a row.
struct Measure {
    /// In the file name.
    file: &'static str,
    /// The x axis's description.
    desc: &'static str,
    of: fn(&Row) -> Option<f64>,
}

fn placed_core(r: &Row) -> Option<&crate::fpga::ecp5::Timing> {
    r.ecp5.iter().find(|p| p.kind == "core").map(|p| &p.timing)
}

/// Whether the area comes from the ECP5's placed core.
fn ecp5_area(results: &Results) -> bool {
    results.spec.synth && results.spec.ecp5.as_ref().is_some_and(|e| e.modules.iter().any(|m| m == "core"))
}

/// The sweep's area measures: the best source it has, for every row alike.
fn measures(results: &Results) -> Vec<Measure> {
    if ecp5_area(results) {
        vec![
            Measure {
                file: "mult18",
                desc: "MULT18X18D (ECP5, placed core)",
                of: |r| Some(placed_core(r)?.mult18 as f64),
            },
            Measure { file: "lut4", desc: "LUT4 (ECP5, placed core)", of: |r| Some(placed_core(r)?.lut4 as f64) },
        ]
    } else if results.spec.xc5v_synth() {
        vec![
            Measure { file: "dsp48e", desc: "DSP48E (yosys, xc5v)", of: |r| Some(r.synth.as_ref()?.dsp48e as f64) },
            Measure { file: "luts", desc: "LUTs (yosys, xc5v)", of: |r| Some(r.synth.as_ref()?.luts as f64) },
        ]
    } else {
        vec![
            Measure {
                file: "dsp48e_est",
                desc: "DSP48E (estimated)",
                of: |r| Some(r.cost.as_ref()?.dsp48e_est as f64),
            },
            Measure {
                file: "register_bits",
                desc: "register bits (netlist)",
                of: |r| Some(r.cost.as_ref()?.register_bits as f64),
            },
        ]
    }
}

/// Where the area comes from, for the report.
pub fn source_text(results: &Results) -> String {
    let m = measures(results);
    let names: Vec<&str> = m.iter().map(|m| m.desc).collect();
    names.join("; ")
}

/// A point's label: K×U, and the leaf size where it is swept.
fn label(results: &Results, r: &Row) -> String {
    if results.spec.leaf_size.len() > 1 { format!("{} L{}", r.shape, r.params.leaf_size) } else { r.shape.to_string() }
}

/// A scene's points: (x, y, label).
type Series = (String, Vec<(f64, f64, String)>);

fn series(results: &Results, x: fn(&Row) -> Option<f64>, y: &dyn Fn(&Row) -> Option<f64>) -> Vec<Series> {
    super::scene_labels(&results.spec.scenes)
        .into_iter()
        .map(|scene| {
            let pts = results
                .rows
                .iter()
                .filter(|r| r.scene == scene)
                .filter_map(|r| Some((x(r)?, y(r)?, label(results, r))))
                .collect();
            (scene, pts)
        })
        .collect()
}

/// Stages plots/throughput_AREA.png per area measure when rows carry the simulated core's
/// figures; returns their paths.
pub fn add_plots(files: &mut OutputSet, dir: &Path, results: &Results) -> Result<Vec<String>> {
    let mut written = Vec::new();
    if !results.spec.core_sim {
        return Ok(written);
    }
    let rays_per_clock = |r: &Row| Some(r.core.as_ref()?.rays_per_clock);
    let mrays = |r: &Row| r.mrays_per_s_at_fmax;
    for m in measures(results) {
        let top = series(results, m.of, &rays_per_clock);
        if top.iter().all(|s| s.1.is_empty()) {
            continue;
        }
        let bottom = series(results, m.of, &mrays);
        let bottom = (!bottom.iter().all(|s| s.1.is_empty())).then_some(bottom);
        let rel = format!("{THROUGHPUT_PLOTS}{}.png", m.file);
        files.add(&dir.join(&rel), &plot(results, &m, &top, bottom.as_deref())?)?;
        written.push(rel);
    }
    Ok(written)
}

fn plot(results: &Results, m: &Measure, top: &[Series], bottom: Option<&[Series]>) -> Result<Vec<u8>> {
    let h = if bottom.is_some() { 2 * H - 80 } else { H };
    let mut rgb = vec![255u8; (W * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (W, h)).into_drawing_area();
        let leaf = if results.spec.leaf_size.len() > 1 { ", L leaf size" } else { "" };
        let shapes = format!("K = {}; U = {}", list(&results.spec.slots), list(&results.spec.units));
        let title = format!("Rays per clock against {} ({shapes}; labels K×U{leaf})", m.desc);
        match bottom {
            Some(bottom) => {
                let (a, b) = root.split_vertically(h / 2);
                panel(&a, &title, m.desc, "rays per clock (Rust simulator)", top)?;
                let title = format!("Mrays/s at the ECP5 Fmax against {}", m.desc);
                panel(&b, &title, m.desc, "Mrays/s at Fmax", bottom)?;
            }
            None => panel(&root, &title, m.desc, "rays per clock (Rust simulator)", top)?,
        }
        root.present().map_err(plot_err)?;
    }
    Ok(encode_png(W, h, &rgb))
}

fn panel(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    lines: &[Series],
) -> Result<()> {
    let all = || lines.iter().flat_map(|s| s.1.iter());
    let x_max = all().map(|p| p.0).fold(1.0, f64::max) * 1.15;
    let y_max = all().map(|p| p.1).fold(f64::MIN_POSITIVE, f64::max) * 1.2;
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 18))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(0f64..x_max, 0f64..y_max)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .draw()
        .map_err(plot_err)?;
    for (i, (scene, pts)) in lines.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let font = (FONT, 13).into_font().color(&BLACK);
        // A dot and its label beside it, offset in pixels.
        let point = |&(x, y, ref l): &(f64, f64, String)| {
            EmptyElement::at((x, y))
                + Circle::new((0, 0), 5, color.filled())
                + Text::new(l.clone(), (8, -14), font.clone())
        };
        chart
            .draw_series(pts.iter().map(point))
            .map_err(plot_err)?
            .label(scene.clone())
            .legend(move |(x, y)| Circle::new((x + 9, y), 5, color.filled()));
    }
    draw_legend(&mut chart)
}

/// A finding: the range of rays per clock over the configurations, and where it is highest.
pub fn finding(results: &Results) -> Option<String> {
    let runs: Vec<(&Row, f64)> =
        results.rows.iter().filter_map(|r| Some((r, r.core.as_ref()?.rays_per_clock))).collect();
    let lo = runs.iter().min_by(|a, b| a.1.total_cmp(&b.1))?;
    let hi = runs.iter().max_by(|a, b| a.1.total_cmp(&b.1))?;
    let at = |r: &Row| format!("{} {}", r.scene, results.spec.set_text(&r.set()));
    Some(format!(
        "Throughput: {:.4} rays per clock ({}) to {:.4} ({}), the whole core in the Rust simulator with K ray slots \
         per traversal unit, U units and one intersection pipeline.",
        lo.1,
        at(lo.0),
        hi.1,
        at(hi.0)
    ))
}
