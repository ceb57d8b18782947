//! The external-memory acceptance frames (issue 29, docs/MEMORY.md "Frames"): each case one
//! whole frame through the external-memory core in the cycle simulator, every pixel checked
//! against the golden model, with the memory side's figures. Prints a Markdown table (the run
//! stops on a mismatch); a progress bar per frame on stderr.
//!
//! cargo run --release --example memory_acceptance -- [--cases all|NAME,NAME…] [--node-cache-kb 32]
//!     [--tri-cache-kb 64]
//!
//! Cases: every built-in scene at 128² (pixel order, L = 40; jackstraws, whose rays test
//! thousands of triangles each, at 16²), teapot-fine at 256² in 8 × 8 tiles,
//! a soup of 200,000 small random triangles (`verify::exact::soups::small_soup`, seed 29) at 64²,
//! and the teapot at 128² with a slow, irregular memory (L = 200, up to 20 clocks of jitter,
//! RVALID paused on 60 of 256 clocks).

use fxrt::cores::memory_params::MemorySpec;
use fxrt::cores::top::{CoreParams, CoreSpec};
use fxrt::model::camera::Camera;
use fxrt::params::Params;
use fxrt::scene::images::SceneRoms;
use fxrt::scene::memory::SceneImage;
use fxrt::scene::{Scene, SceneSource};
use fxrt::verify::feed::tile_order;
use fxrt::verify::frame::{frame_rays, mismatches, progress_bar};
use fxrt::verify::frame_memory::simulate_external;
use fxrt::verify::memory::MemoryTiming;

/// One frame: a scene, its size, the feed order and the memory's timing.
struct Case {
    name: &'static str,
    scene: &'static str,
    size: u32,
    tiles: bool,
    timing: MemoryTiming,
}

/// Triangles of the large soup, and its seed.
const SOUP_TRIANGLES: usize = 200_000;
const SOUP_SEED: u64 = 29;

fn cases() -> Vec<Case> {
    let l40 = MemoryTiming::default();
    let slow = MemoryTiming { latency: 200, extra_delay: 20, pause_in_256: 60, seed: 7, ..l40 };
    let at = |name, scene, size, tiles, timing| Case { name, scene, size, tiles, timing };
    vec![
        at("teapot", "teapot", 128, false, l40),
        // Thousands of triangle tests a ray (DECISIONS, "Seen and left alone"): hours at 128².
        at("jackstraws", "jackstraws", 16, false, l40),
        at("thin", "thin", 128, false, l40),
        at("random", "random", 128, false, l40),
        at("cornell", "cornell", 128, false, l40),
        at("teapot-fine", "teapot-fine", 128, false, l40),
        at("teapot-fine-256", "teapot-fine", 256, true, l40),
        at("soup", "soup", 64, false, l40),
        at("teapot-slow", "teapot", 128, false, slow),
    ]
}

fn scene_of(name: &str) -> Result<Scene, Box<dyn std::error::Error>> {
    let params = Params::default();
    Ok(if name == "soup" {
        let tris = fxrt::verify::exact::soups::small_soup(SOUP_SEED, SOUP_TRIANGLES);
        Scene::build(&format!("soup{}k", SOUP_TRIANGLES / 1000), tris, &params)?
    } else {
        Scene::load(&SceneSource::Builtin(name.into()), &params)?
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let get = |flag: &str| args.iter().position(|a| a == flag).and_then(|i| args.get(i + 1)).cloned();
    let wanted = get("--cases").unwrap_or_else(|| "all".into());
    let spec = MemorySpec {
        node_cache_kb: get("--node-cache-kb").map_or(Ok(MemorySpec::default().node_cache_kb), |s| s.parse())?,
        tri_cache_kb: get("--tri-cache-kb").map_or(Ok(MemorySpec::default().tri_cache_kb), |s| s.parse())?,
        ..MemorySpec::default()
    };
    let chosen: Vec<Case> =
        cases().into_iter().filter(|c| wanted == "all" || wanted.split(',').any(|w| w == c.name)).collect();
    if chosen.is_empty() {
        return Err(format!(
            "--cases {wanted}: none of {}",
            cases().iter().map(|c| c.name).collect::<Vec<_>>().join(", ")
        )
        .into());
    }
    println!(
        "External memory, {}-bit port, {}-byte lines, {} × {} KB node caches and a {} KB triangle cache, {} ways.\n",
        spec.shape.mem_bits,
        spec.shape.line_bytes,
        CoreSpec::default().units,
        spec.node_cache_kb,
        spec.tri_cache_kb,
        spec.ways
    );
    println!(
        "| case | scene (triangles) | frame | order | memory | rays | wrong | clocks | rays per clock | bytes per ray | reads per ray | node hit | triangle hit | R busy | stall |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for c in &chosen {
        let scene = scene_of(c.scene)?;
        let roms = SceneRoms::of(&scene);
        let cam = Camera::default_for(&scene, c.size, c.size);
        let rays = frame_rays(&scene, &cam);
        let rays = if c.tiles { tile_order(&rays, |r| r.pixel, c.size, 8) } else { rays };
        let shape =
            CoreSpec { id_width: fxrt::scene::rom::addr_bits((c.size * c.size) as usize), ..CoreSpec::default() };
        let p = CoreParams::external(&roms, &shape, spec)?;
        let image = SceneImage::build(&roms, spec.shape)?;
        let bar = progress_bar(rays.len() as u64, c.name);
        let (results, stats, ms) =
            simulate_external(&p, &roms, &image, &rays, c.timing, &fxrt::verify::feed::Stalls::none(), &|n| {
                bar.set_position(n)
            })?;
        bar.finish_and_clear();
        let wrong = mismatches(&scene, &rays, &results);
        let t = c.timing;
        println!(
            "| {} | {} ({}) | {}² | {} | L {}{}{} | {} | {wrong} | {} | {:.4} | {:.1} | {:.2} | {:.4} | {:.4} | {:.2} | {:.3} |",
            c.name,
            scene.name,
            roms.tri_count(),
            c.size,
            if c.tiles { "tiles" } else { "pixels" },
            t.latency,
            if t.extra_delay > 0 { format!(", jitter {}", t.extra_delay) } else { String::new() },
            if t.pause_in_256 > 0 { format!(", pauses {}/256", t.pause_in_256) } else { String::new() },
            rays.len(),
            stats.cycles,
            stats.rays_per_clock(),
            ms.figures.mem_bytes_per_ray,
            ms.figures.mem_reads_per_ray,
            ms.figures.node_cache_hit_rate,
            ms.figures.tri_cache_hit_rate,
            ms.figures.mem_busy,
            ms.figures.memory_stall_fraction
        );
        if wrong > 0 {
            return Err(format!("{}: {wrong} rays differ from the golden model", c.name).into());
        }
    }
    Ok(())
}
