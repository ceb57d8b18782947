//! What `fxrt scene` reports: scene.json and the `--stats` text.

use super::rom::{Layout, Word};
use super::{Scene, edge_histogram};
use serde_json::{Value, json};
use std::fmt::Write as _;

pub fn scene_json(scene: &Scene, roms: &[(Layout, Vec<Word>)]) -> Value {
    json!({
        "fxrt_version": env!("CARGO_PKG_VERSION"),
        "scene": scene.name,
        "params": scene.params,
        "edge_shift_used": scene.edge_shift,
        "world_to_grid": {
            "formula": "grid = round((world - min) * scale), clamped to [0, 2^n - 1]",
            "min": scene.transform.min,
            "scale": scene.transform.scale,
        },
        "grid_box_hi": scene.grid_box.hi,
        "triangles": scene.counts,
        "bih": scene.bih_stats,
        "roms": roms.iter().map(|(l, w)| json!({ "rom": l.rom, "width": l.width, "depth": w.len(), "fields": l.fields })).collect::<Vec<_>>(),
    })
}

pub fn stats_text(scene: &Scene) -> String {
    let mut s = String::new();
    let c = &scene.counts;
    let b = &scene.bih_stats;
    let _ = writeln!(
        s,
        "triangles: {} input, {} degenerate (removed), {} with clamped edges, {} stored",
        c.input, c.degenerate, c.clamped, c.stored
    );
    let _ = writeln!(s, "edge shift E: {} ({})", scene.edge_shift, scene.params.edge_shift);
    let _ = writeln!(
        s,
        "BIH: {} nodes ({} inner, {} leaves, {} empty), depth {} (stack {}), leaf size mean {:.2} max {} ({} over --leaf-size)",
        b.nodes,
        b.inner,
        b.leaves,
        b.empty_leaves,
        b.depth,
        scene.params.stack_depth,
        b.mean_leaf_size,
        b.max_leaf_size,
        b.oversized_leaves
    );
    let comps = scene.edge_components();
    let bins = edge_histogram(&comps);
    let total = comps.len().max(1) as f64;
    let _ = writeln!(s, "edge components |e1p|,|e1q|,|e2p|,|e2q| (seed 001 fig. 2.1), relative frequency, log scale:");
    for (i, &n) in bins.iter().enumerate() {
        let label = if i < 9 {
            format!("[{:.4}, {:.4})", i as f64 * 1e-4, (i + 1) as f64 * 1e-4)
        } else {
            ">= 0.0009        ".to_string()
        };
        let freq = n as f64 / total;
        // Bar length on a log scale: 1e-6 → 0, 1 → 48 characters.
        let bar = if n == 0 { 0 } else { ((freq.log10() + 6.0).max(0.0) * 8.0).round() as usize };
        let _ = writeln!(s, "  {label} {freq:>9.6} {}", "#".repeat(bar));
    }
    s
}
