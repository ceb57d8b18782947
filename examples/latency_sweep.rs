//! Rays per clock and bytes per ray of an external-memory core against the memory's latency
//! (issue 29, docs/MEMORY.md): one frame through the core in the cycle simulator for each
//! latency, the memory model otherwise at its defaults, next to the same core with its scene on
//! chip. Prints a Markdown table; writes the plot as a PNG. Every frame is checked pixel by
//! pixel against the golden model (the run stops on a mismatch).
//!
//! cargo run --release --example latency_sweep -- [--scene teapot] [--size 64]
//!     [--latency 1,20,40,80,120,160,200] [--tiles] [--out latency.png]

use fxrt::cores::memory_params::MemorySpec;
use fxrt::cores::top::{CoreParams, CoreSpec};
use fxrt::model::camera::Camera;
use fxrt::params::Params;
use fxrt::scene::images::SceneRoms;
use fxrt::scene::memory::SceneImage;
use fxrt::scene::{Scene, SceneSource};
use fxrt::sweep::draw::{FONT, H, W, draw_legend, plot_err, register_font};
use fxrt::verify::feed::{Stalls, tile_order};
use fxrt::verify::frame::{frame_rays, mismatches, simulate_rust};
use fxrt::verify::frame_memory::simulate_external;
use fxrt::verify::memory::MemoryTiming;
use plotters::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let get = |flag: &str| args.iter().position(|a| a == flag).and_then(|i| args.get(i + 1)).cloned();
    let scene_name = get("--scene").unwrap_or_else(|| "teapot".into());
    let size: u32 = get("--size").map_or(Ok(64), |s| s.parse())?;
    let latencies: Vec<u32> = get("--latency")
        .unwrap_or_else(|| "1,20,40,80,120,160,200".into())
        .split(',')
        .map(|s| s.parse())
        .collect::<Result<_, _>>()?;
    let out = get("--out").unwrap_or_else(|| "latency.png".into());
    let tiles = args.iter().any(|a| a == "--tiles");
    let scene = Scene::load(&SceneSource::Builtin(scene_name.clone()), &Params::default())?;
    let roms = SceneRoms::of(&scene);
    let cam = Camera::default_for(&scene, size, size);
    let rays = frame_rays(&scene, &cam);
    let rays = if tiles { tile_order(&rays, |r| r.pixel, size, 8) } else { rays };
    let shape = CoreSpec { id_width: fxrt::scene::rom::addr_bits((size * size) as usize), ..CoreSpec::default() };
    let onchip = CoreParams::shaped(&roms, &shape);
    let (chip_results, chip) = simulate_rust(&onchip, &roms, &rays, &Stalls::none(), &|_| ());
    assert_eq!(mismatches(&scene, &rays, &chip_results), 0, "on chip");
    let spec = MemorySpec::default();
    let p = CoreParams::external(&roms, &shape, spec)?;
    let image = SceneImage::build(&roms, spec.shape)?;
    println!(
        "{scene_name} {size}², {} rays, {}; on chip: {:.4} rays per clock",
        rays.len(),
        if tiles { "8×8 tiles" } else { "pixel order" },
        chip.rays_per_clock()
    );
    println!("\n| latency | rays per clock | × on chip | bytes per ray | node hit | triangle hit | R busy | stall |");
    println!("|---|---|---|---|---|---|---|---|");
    let mut points = Vec::new();
    for &latency in &latencies {
        let timing = MemoryTiming { latency, ..MemoryTiming::default() };
        let (results, stats, ms) = simulate_external(&p, &roms, &image, &rays, timing, &Stalls::none(), &|_| ())?;
        assert_eq!(mismatches(&scene, &rays, &results), 0, "latency {latency}");
        let rpc = stats.rays_per_clock();
        println!(
            "| {latency} | {rpc:.4} | {:.2} | {:.1} | {:.4} | {:.4} | {:.2} | {:.3} |",
            rpc / chip.rays_per_clock(),
            ms.figures.mem_bytes_per_ray,
            ms.figures.node_cache_hit_rate,
            ms.figures.tri_cache_hit_rate,
            ms.figures.mem_busy,
            ms.figures.memory_stall_fraction
        );
        points.push((latency as f64, rpc));
    }
    register_font();
    let mut rgb = vec![255u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (W, H)).into_drawing_area();
        let x_max = latencies.iter().copied().max().unwrap_or(1) as f64 * 1.05;
        let y_max = points.iter().map(|p| p.1).fold(chip.rays_per_clock(), f64::max) * 1.2;
        let mut chart = ChartBuilder::on(&root)
            .caption(format!("{scene_name} {size}²: rays per clock against memory latency"), (FONT, 20))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(0f64..x_max, 0f64..y_max)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("latency L, clocks from address to first beat")
            .y_desc("rays per clock")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .draw()
            .map_err(plot_err)?;
        let red = RGBColor(214, 39, 40);
        chart
            .draw_series(LineSeries::new(points.clone(), red.stroke_width(2)))
            .map_err(plot_err)?
            .label("external memory (64-bit port, 2 × 32 KB node + 64 KB triangle cache)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], red.stroke_width(2)));
        chart.draw_series(points.iter().map(|&pt| Circle::new(pt, 4, red.filled()))).map_err(plot_err)?;
        let grey = RGBColor(110, 110, 110);
        chart
            .draw_series(LineSeries::new(
                vec![(0.0, chip.rays_per_clock()), (x_max, chip.rays_per_clock())],
                grey.stroke_width(2),
            ))
            .map_err(plot_err)?
            .label("the same core, scene on chip")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey.stroke_width(2)));
        draw_legend(&mut chart)?;
        root.present().map_err(plot_err)?;
    }
    std::fs::write(&out, fxrt::render::encode_png(W, H, &rgb))?;
    println!("\nplot: {out}");
    Ok(())
}
