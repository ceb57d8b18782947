//! `fxrt bench --against-embree`: the golden model and Embree trace the same camera's rays in
//! one run, one thread and all threads, for two views of the built-in teapot; a table of both
//! throughputs and their ratio (docs/PERFORMANCE.md). Embree runs in a subprocess
//! (`render::embree`); its hit count must be the golden model's within 1 % of the pixels, or the
//! two did not trace the same rays (exit 1).

use super::config::thread_pool;
use crate::error::Result;
use crate::model::camera::Camera;
use crate::params::Params;
use crate::render::embree::{self, EmbreeReport};
use crate::render::{self, tracer::GoldenTracer};
use crate::scene::{Scene, SceneSource};

/// The distant view's eye: on the framing view's line of sight, this many times as far from
/// the teapot's centre, with the same field of view: the teapot at half the size, so 6.0 % of
/// the rays hit it (62,392 of 1024², against 24.4 % in the framing view; docs/PERFORMANCE.md)
/// and the speed is mostly that of rays that miss.
pub const DISTANT_FACTOR: f64 = 2.0;

/// The two views: `fxrt bench`'s framing camera and the distant one.
pub fn views(scene: &Scene, width: u32, height: u32) -> [(&'static str, Camera); 2] {
    let framing = Camera::default_for(scene, width, height);
    let eye = std::array::from_fn(|k| framing.at[k] + DISTANT_FACTOR * (framing.eye[k] - framing.at[k]));
    [("framing", framing), ("distant", Camera { eye, ..framing })]
}

/// Which of the golden model's code paths `render` takes on this CPU (`render::fast`).
fn golden_path(t: &GoldenTracer) -> &'static str {
    use crate::render::fast::GoldenPath;
    match t.fast.path() {
        GoldenPath::Avx512 => "AVX-512 packets of 16 rays (render::fast::packet)",
        GoldenPath::Avx2 => "AVX2 packets of 8 rays (render::fast::packet; no AVX-512F/DQ, or $FXRT_GOLDEN_PATH=avx2)",
        GoldenPath::Scalar => "scalar i64 path, one ray at a time (no AVX2, or $FXRT_GOLDEN_PATH=scalar)",
        _ => "the 128-bit reference path (the widths allow no other, or $FXRT_GOLDEN_PATH=reference)",
    }
}

/// The golden model's best of `repeat` renders of `cam` on `threads` threads: (Mrays/s, hits).
fn golden_speed(scene: &Scene, t: &GoldenTracer, cam: &Camera, threads: usize, repeat: u32) -> Result<(f64, u64)> {
    let pool = thread_pool(Some(threads))?;
    let (mut best, mut hits, mut rays) = (f64::INFINITY, 0, 0);
    for _ in 0..repeat {
        let f = pool.install(|| render::render(scene, t, cam, false, false));
        (best, hits, rays) = (best.min(f.seconds), f.hits, f.rays);
    }
    Ok((rays as f64 / best.max(1e-9) / 1e6, hits))
}

/// One line of the table.
struct Row {
    view: &'static str,
    threads: usize,
    fxrt: f64,
    embree: f64,
}

/// Whether the hit counts agree within 1 % of the pixels (float Embree against the integer
/// golden model: rays grazing an edge may go either way, but not many).
pub fn hits_agree(golden: u64, embree: u64, pixels: u64) -> bool {
    golden.abs_diff(embree) * 100 <= pixels
}

/// Runs the comparison; Ok(false) when a view's hit counts disagree.
pub fn against_embree(width: u32, height: u32, threads: usize, repeat: u32) -> Result<bool> {
    // Refused before any work when embreex is missing.
    let python = embree::require()?;
    let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default())?;
    let counts = if threads == 1 { vec![1] } else { vec![1, threads] };
    let golden = GoldenTracer::new(&scene);
    let dir = tempfile::tempdir().map_err(|e| crate::error::Error::new("temporary folder", e.to_string()))?;
    let (mut rows, mut checks, mut versions) = (Vec::new(), Vec::new(), None::<EmbreeReport>);
    for (view, cam) in views(&scene, width, height) {
        eprintln!("bench: {view} view: Embree, then the golden model");
        let report = embree::measure(&python, dir.path(), &scene, &cam, &counts, repeat)?;
        let mut golden_hits = 0;
        for &t in &counts {
            let (fxrt, hits) = golden_speed(&scene, &golden, &cam, t, repeat)?;
            let embree = report.mrays_per_s(t).unwrap_or(f64::NAN);
            golden_hits = hits;
            rows.push(Row { view, threads: t, fxrt, embree });
        }
        checks.push((view, golden_hits, report.hits));
        versions = Some(report);
    }
    let r = versions.expect("two views ran");
    println!("teapot ({} triangles), {width}x{height} primary rays, best of {repeat}", scene.world.len());
    println!("fxrt: the golden model, {}", golden_path(&golden));
    println!("Embree {} through embreex {} (rtcIntersect1 per ray, float32)", r.embree, r.embreex);
    println!("{:<8} {:>7} {:>13} {:>15} {:>12}", "view", "threads", "fxrt Mrays/s", "Embree Mrays/s", "fxrt/Embree");
    for row in &rows {
        println!(
            "{:<8} {:>7} {:>13.2} {:>15.2} {:>12.3}",
            row.view,
            row.threads,
            row.fxrt,
            row.embree,
            row.fxrt / row.embree
        );
    }
    let pixels = width as u64 * height as u64;
    let mut all = true;
    for (view, g, e) in checks {
        let ok = hits_agree(g, e, pixels);
        all &= ok;
        let verdict = if ok { "agree (within 1 % of pixels)" } else { "DISAGREE (more than 1 % of pixels apart)" };
        println!("{view}: hits fxrt {g}, Embree {e} of {pixels} rays: {verdict}");
    }
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_distant_view_looks_at_the_same_point_from_further_away() {
        let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
        let [(_, f), (_, d)] = views(&scene, 16, 16);
        assert_eq!((d.at, d.up, d.fov_deg), (f.at, f.up, f.fov_deg));
        let dist = |c: &Camera| (0..3).map(|k| (c.eye[k] - c.at[k]).powi(2)).sum::<f64>().sqrt();
        assert!((dist(&d) / dist(&f) - DISTANT_FACTOR).abs() < 1e-9);
        assert!(hits_agree(1000, 1040, 4096) && !hits_agree(1000, 1041, 4096));
    }
}
