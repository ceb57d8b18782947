//! Plots (plotters, PNG): wrong pixels against each swept parameter that can change the image,
//! and against DSP48E with the Pareto front; with `--family ecp5`, Fmax against each swept
//! parameter; with `--core-sim`, throughput against area (`throughput.rs`). Text uses DejaVu
//! Sans compiled in, so no system font is needed.

use super::draw::{FONT, H, W, draw_legend, plot_err, register_font};
use super::eval::Row;
use super::grid::series;
use super::output::Results;
use super::summary::{pareto_front, set_summaries};
use super::{Axis, Plan, set_label};
use crate::error::Result;
use crate::io::OutputSet;
use crate::render::encode_png;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use std::path::Path;

/// Where a count of 0 is drawn on the logarithmic axes.
const ZERO: f64 = 0.5;

/// Where the Fmax plots of `--family ecp5` go: plots/fmax_PARAM.png.
pub const FMAX_PLOTS: &str = "plots/fmax_";

/// Where the plots of `--memory external --core-sim` go: plots/memory_WHAT_PARAM.png.
pub const MEMORY_PLOTS: &str = "plots/memory_";

/// Stages plots/error_PARAM.png per swept parameter that can change the image, with
/// `--family ecp5` plots/fmax_PARAM.png per swept parameter, plots/pareto_dsp48e.png, and with
/// `--core-sim` plots/throughput_AREA.png per area measure.
pub fn add_plots(files: &mut OutputSet, dir: &Path, results: &Results, plan: &Plan) -> Result<Vec<String>> {
    register_font();
    let mut written = Vec::new();
    for axis in results.spec.swept_axes().into_iter().filter(|a| a.changes_image()) {
        let rel = format!("plots/error_{}.png", axis.name());
        files.add(&dir.join(&rel), &error_plot(results, plan, axis)?)?;
        written.push(rel);
    }
    if let Some(e) = &results.spec.ecp5 {
        for axis in results.spec.swept_axes() {
            let rel = format!("{FMAX_PLOTS}{}.png", axis.name());
            files.add(&dir.join(&rel), &fmax_plot(results, plan, axis, &e.modules)?)?;
            written.push(rel);
        }
    }
    if !set_summaries(results).is_empty() {
        let rel = "plots/pareto_dsp48e.png".to_string();
        files.add(&dir.join(&rel), &pareto_plot(results)?)?;
        written.push(rel);
    }
    written.extend(super::throughput::add_plots(files, dir, results)?);
    if results.spec.memory.is_some() && results.spec.core_sim {
        for axis in results.spec.swept_axes() {
            for (what, file) in
                [(MemoryFigure::RaysPerClock, "rays_per_clock"), (MemoryFigure::BytesPerRay, "bytes_per_ray")]
            {
                let rel = format!("{MEMORY_PLOTS}{file}_{}.png", axis.name());
                files.add(&dir.join(&rel), &memory_plot(results, plan, axis, what)?)?;
                written.push(rel);
            }
        }
    }
    Ok(written)
}

/// What a memory plot draws along an axis.
#[derive(Clone, Copy)]
enum MemoryFigure {
    RaysPerClock,
    BytesPerRay,
}

/// plots/memory_WHAT_PARAM.png: rays per clock or bytes read from memory per ray along `axis`
/// (the others at the base set), a line per scene.
fn memory_plot(results: &Results, plan: &Plan, axis: Axis, what: MemoryFigure) -> Result<Vec<u8>> {
    let y: &dyn Fn(&Row) -> Option<f64> = match what {
        MemoryFigure::RaysPerClock => &|r| Some(r.core.as_ref()?.rays_per_clock),
        MemoryFigure::BytesPerRay => &|r| Some(r.memory.as_ref()?.figures.mem_bytes_per_ray),
    };
    let (title, y_desc) = match what {
        MemoryFigure::RaysPerClock => ("Rays per clock, scene in external memory,", "rays per clock (Rust simulator)"),
        MemoryFigure::BytesPerRay => ("Bytes read from memory per ray", "bytes per ray (R beats × port width)"),
    };
    let lines: Vec<Line> = super::scene_labels(&results.spec.scenes)
        .into_iter()
        .map(|scene| {
            let pts = points(results, plan, &scene, axis, y);
            (scene, pts)
        })
        .collect();
    let top = lines.iter().flat_map(|l| l.1.iter().map(|p| p.1)).fold(f64::MIN_POSITIVE, f64::max) * 1.2;
    let chart = AxisChart::new(results, plan, axis, title, y_desc);
    axis_chart(&AxisChart { lines, ..chart }, 0f64..top)
}

/// The points of one scene along `axis`: (position in the axis's list, y) for each row where
/// `y` gives a value.
fn points(results: &Results, plan: &Plan, scene: &str, axis: Axis, y: &dyn Fn(&Row) -> Option<f64>) -> Vec<(i32, f64)> {
    let values = results.spec.values(axis);
    series(results, plan, scene, axis)
        .into_iter()
        .filter_map(|r| Some((values.iter().position(|v| *v == axis.value(&r.set()))? as i32, y(r)?)))
        .collect()
}

fn error_plot(results: &Results, plan: &Plan, axis: Axis) -> Result<Vec<u8>> {
    let labels = super::scene_labels(&results.spec.scenes);
    let wrong = |r: &Row| Some((r.quality.as_ref()?.wrong_pixels as f64).max(ZERO));
    let lines: Vec<Line> =
        labels.iter().map(|scene| (scene.clone(), points(results, plan, scene, axis, &wrong))).collect();
    let top = lines.iter().flat_map(|l| l.1.iter().map(|p| p.1)).fold(10.0, f64::max) * 2.0;
    let chart = AxisChart::new(results, plan, axis, "Wrong pixels", "wrong pixels vs f64 (0 drawn at 0.5)");
    axis_chart(&AxisChart { lines, ..chart }, (ZERO..top).log_scale())
}

/// plots/fmax_PARAM.png: each placed module's Fmax along `axis`, per scene, and the target.
fn fmax_plot(results: &Results, plan: &Plan, axis: Axis, modules: &[String]) -> Result<Vec<u8>> {
    let mut lines: Vec<Line> = Vec::new();
    for scene in super::scene_labels(&results.spec.scenes) {
        for kind in modules {
            let fmax = |r: &Row| r.ecp5.iter().find(|p| &p.kind == kind).map(|p| p.timing.fmax_mhz);
            lines.push((format!("{scene} · {kind}"), points(results, plan, &scene, axis, &fmax)));
        }
    }
    let target = results.spec.target_mhz as f64;
    let top = lines.iter().flat_map(|l| l.1.iter().map(|p| p.1)).fold(target, f64::max) * 1.15;
    let chart = AxisChart::new(results, plan, axis, "ECP5 Fmax", "Fmax, MHz (LFE5U-85F, speed 6)");
    axis_chart(&AxisChart { lines, level: Some((format!("target {target} MHz"), target)), ..chart }, 0f64..top)
}

/// A legend and its points: (position in the axis's list, y).
type Line = (String, Vec<(i32, f64)>);

/// A plot of lines along one swept parameter.
struct AxisChart<'a> {
    title: String,
    y_desc: &'a str,
    values: Vec<String>,
    axis: Axis,
    lines: Vec<Line>,
    /// A horizontal line with its legend.
    level: Option<(String, f64)>,
}

impl<'a> AxisChart<'a> {
    /// "`what` against P (the base set's other parameters)", no lines yet.
    fn new(results: &Results, plan: &Plan, axis: Axis, what: &str, y_desc: &'a str) -> AxisChart<'a> {
        let others = results
            .spec
            .named_axes()
            .into_iter()
            .filter(|&a| a != axis)
            .map(|a| format!("{}={}", a.symbol(), a.value(&plan.base)))
            .collect::<Vec<_>>()
            .join(" ");
        let title = format!("{what} against {} ({others})", axis.symbol());
        AxisChart { title, y_desc, values: results.spec.values(axis), axis, lines: Vec::new(), level: None }
    }
}

fn axis_chart<Y>(c: &AxisChart, y_range: Y) -> Result<Vec<u8>>
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let values = &c.values;
    let mut rgb = vec![255u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (W, H)).into_drawing_area();
        let mut chart = ChartBuilder::on(&root)
            .caption(&c.title, (FONT, 20))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(-0.5f64..(values.len() as f64 - 0.5), y_range)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc(c.axis.symbol())
            .y_desc(c.y_desc)
            .x_labels(values.len())
            .x_label_formatter(&|x| {
                let i = x.round();
                if (x - i).abs() < 1e-6 && i >= 0.0 {
                    values.get(i as usize).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .draw()
            .map_err(plot_err)?;
        if let Some((label, y)) = &c.level {
            // Darker and wider than the mesh line it may lie on.
            let grey = RGBColor(90, 90, 90);
            let ends = vec![(-0.5, *y), (values.len() as f64 - 0.5, *y)];
            chart
                .draw_series(LineSeries::new(ends, grey.stroke_width(3)))
                .map_err(plot_err)?
                .label(label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], grey.stroke_width(3)));
        }
        for (i, (label, pts)) in c.lines.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            let pts: Vec<(f64, f64)> = pts.iter().map(|&(x, y)| (x as f64, y)).collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                .map_err(plot_err)?
                .label(label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2)));
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled()))).map_err(plot_err)?;
        }
        draw_legend(&mut chart)?;
        root.present().map_err(plot_err)?;
    }
    Ok(encode_png(W, H, &rgb))
}

fn pareto_plot(results: &Results) -> Result<Vec<u8>> {
    let sets = set_summaries(results);
    let front = pareto_front(&sets);
    let y = |w: u64| (w as f64).max(ZERO);
    let x_max = sets.iter().map(|s| s.dsp48e).max().unwrap_or(1) as f64 * 1.1 + 1.0;
    let y_top = sets.iter().map(|s| y(s.wrong)).fold(10.0, f64::max) * 2.0;
    let source = if results.spec.xc5v_synth() { "yosys" } else { "estimated" };
    let mut rgb = vec![255u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (W, H)).into_drawing_area();
        let mut chart = ChartBuilder::on(&root)
            .caption(format!("Wrong pixels (all scenes) against DSP48E ({source}); Pareto front in red"), (FONT, 20))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(0f64..x_max, (ZERO..y_top).log_scale())
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("DSP48E slices")
            .y_desc("wrong pixels vs f64 (0 drawn at 0.5)")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .draw()
            .map_err(plot_err)?;
        let grey = RGBColor(150, 150, 150);
        chart
            .draw_series(sets.iter().map(|s| Circle::new((s.dsp48e as f64, y(s.wrong)), 4, grey.filled())))
            .map_err(plot_err)?;
        let red = RGBColor(214, 39, 40);
        let pts: Vec<(f64, f64)> = front.iter().map(|&i| (sets[i].dsp48e as f64, y(sets[i].wrong))).collect();
        chart.draw_series(LineSeries::new(pts.clone(), red.stroke_width(2))).map_err(plot_err)?;
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 5, red.filled()))).map_err(plot_err)?;
        chart
            .draw_series(front.iter().map(|&i| {
                let s = &sets[i];
                Text::new(
                    set_label(&s.set()),
                    (s.dsp48e as f64, y(s.wrong) * 1.25),
                    (FONT, 12).into_font().color(&BLACK),
                )
            }))
            .map_err(plot_err)?;
        root.present().map_err(plot_err)?;
    }
    Ok(encode_png(W, H, &rgb))
}
