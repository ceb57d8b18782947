//! The sweep folder: results.json / results.csv, the cache of finished configurations, and the
//! images copied out of it.
//!
//! ```text
//! DIR/results.json  results.csv  report.md
//! DIR/images/SCENE/LABEL.png, LABEL_errors.png
//! DIR/grids/SCENE_PARAM.png    DIR/plots/*.png
//! DIR/cache/KEY.json, KEY.png, KEY_errors.png   (every configuration ever finished here;
//!                                               `--cache` may put it elsewhere, e.g. shared by shards)
//! ```

use super::eval::{Evaluated, Row};
use super::{Skipped, SweepSpec};
use crate::error::{Error, Result};
use crate::io::OutputSet;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// results.json: the spec, the plan's size and every finished row, in index order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Results {
    pub fxrt: String,
    pub spec: SweepSpec,
    /// Configurations in the whole sweep (all shards).
    pub configurations: usize,
    /// `I/N` for a shard's folder; absent for a whole sweep.
    pub shard: Option<String>,
    pub skipped: Vec<Skipped>,
    pub rows: Vec<Row>,
}

/// The files of one cache entry in the cache folder `cache`.
fn cache_files(cache: &Path, key: &str) -> [PathBuf; 3] {
    [cache.join(format!("{key}.json")), cache.join(format!("{key}.png")), cache.join(format!("{key}_errors.png"))]
}

/// Whether `cache` holds the entry `key`.
pub fn has_cached(cache: &Path, key: &str) -> bool {
    cache_files(cache, key)[0].is_file()
}

/// A finished configuration from the cache, renumbered for this sweep; None if absent,
/// unreadable or incomplete (it is then computed again: a missing yosys may be installed
/// since).
pub fn load_cached(dir: &Path, key: &str, index: usize, scene: &str) -> Option<Row> {
    let [json, png, errors] = cache_files(dir, key);
    let mut row: Row = serde_json::from_slice(&std::fs::read(json).ok()?).ok()?;
    if row.key != key || row.error.is_some() || (row.quality.is_some() && !(png.is_file() && errors.is_file())) {
        return None;
    }
    row.index = index;
    row.scene = scene.to_string();
    Some(row)
}

/// Stores a finished configuration: its row and images placed together, so a row in the cache
/// has its images (the row last: a shard sharing the cache takes an entry by its row).
pub fn store_cached(dir: &Path, e: &Evaluated) -> Result<()> {
    let [json, png, errors] = cache_files(dir, &e.row.key);
    let mut files = OutputSet::new();
    if !e.render_png.is_empty() {
        files.add(&png, &e.render_png)?;
        files.add(&errors, &e.errors_png)?;
    }
    files.add(&json, &serde_json::to_vec_pretty(&e.row).expect("rows serialise"))?;
    files.commit()
}

/// Copies a cache entry from one cache folder to another (merging shards), whole.
pub fn copy_cached(from: &Path, to: &Path, key: &str) -> Result<()> {
    let mut files = OutputSet::new();
    for (src, dst) in cache_files(from, key).iter().zip(cache_files(to, key)) {
        if src.is_file() {
            let bytes = std::fs::read(src).map_err(|e| Error::file(src, format!("cannot read: {e}")))?;
            files.add(&dst, &bytes)?;
        }
    }
    files.commit()
}

/// The render and error images of a row, from the cache.
pub fn cached_images(dir: &Path, key: &str) -> Result<(Vec<u8>, Vec<u8>)> {
    let [_, png, errors] = cache_files(dir, key);
    let read = |p: &Path| std::fs::read(p).map_err(|e| Error::file(p, format!("cannot read: {e}")));
    Ok((read(&png)?, read(&errors)?))
}

pub fn read_results(dir: &Path) -> Result<Results> {
    let path = dir.join("results.json");
    let bytes = std::fs::read(&path).map_err(|e| Error::file(&path, format!("cannot read: {e}")))?;
    serde_json::from_slice(&bytes).map_err(|e| Error::file(&path, format!("not a fxrt sweep result: {e}")))
}

/// The columns of results.csv in every sweep (`csv_columns` adds the core's shape after
/// `stack_depth`, `CORE_COLUMNS` after `core_mismatches` and the ECP5 columns before the last three).
pub const CSV_COLUMNS: &[&str] = &[
    "index",
    "scene",
    "n",
    "m",
    "edge_shift",
    "e_used",
    "t",
    "c",
    "leaf_size",
    "stack_depth",
    "rays",
    "ref_hits",
    "hits",
    "false_misses",
    "false_hits",
    "other_triangle",
    "other_surface",
    "wrong_pixels",
    "wrong_rate",
    "diff_vs_default",
    "t_rel_mean",
    "t_rel_max",
    "tris_input",
    "tris_degenerate",
    "tris_clamped",
    "tris_stored",
    "div_latency",
    "isect_latency",
    "rom_bits",
    "dsp48e_est",
    "register_bits",
    "luts",
    "srl_luts",
    "ffs",
    "dsp48e",
    "bram18",
    "cycles_per_ray",
    "pipeline_fill",
    "max_stack_depth",
    "core_mismatches",
    "image",
    "error",
    "key",
];

/// Columns of the core's shape, after `stack_depth`, in sweeps whose `--slots` or `--units`
/// are not the defaults or whose cores have several pipelines (`--device`).
pub const SHAPE_COLUMNS: [&str; 3] = ["slots", "units", "pipelines"];

/// Columns of `--core-sim` sweeps after `core_mismatches` (`fxrt sim`'s figures).
pub const CORE_COLUMNS: [&str; 4] =
    ["rays_per_clock", "triangle_tests_per_ray", "node_steps_per_ray", "slot_occupancy"];

/// `fields` (one per `CSV_COLUMNS`) with the shape's and the core's cells where the sweep has
/// those columns.
fn with_optional(spec: &SweepSpec, mut fields: Vec<String>, shape: [String; 3], core: [String; 4]) -> Vec<String> {
    let after = |c: &str| CSV_COLUMNS.iter().position(|x| *x == c).expect("a column of CSV_COLUMNS") + 1;
    // The later columns first, so that the earlier position still holds.
    if spec.core_sim {
        let at = after("core_mismatches");
        fields.splice(at..at, core);
    }
    if !spec.default_core_shape() {
        let at = after("stack_depth");
        fields.splice(at..at, shape);
    }
    fields
}

fn csv_record(r: &Row) -> Vec<String> {
    let opt = |v: Option<String>| v.unwrap_or_default();
    let p = &r.params;
    let mut rec = vec![
        r.index.to_string(),
        r.scene.clone(),
        p.n.to_string(),
        p.m.to_string(),
        p.edge_shift.to_string(),
        opt(r.e_used.map(|e| e.to_string())),
        p.t.to_string(),
        p.c.to_string(),
        p.leaf_size.to_string(),
        p.stack_depth.to_string(),
    ];
    let q = r.quality.as_ref();
    let qf = |f: &dyn Fn(&super::eval::Quality) -> String| opt(q.map(f));
    rec.extend([
        qf(&|q| q.rays.to_string()),
        qf(&|q| q.ref_hits.to_string()),
        qf(&|q| q.hits.to_string()),
        qf(&|q| q.false_misses.to_string()),
        qf(&|q| q.false_hits.to_string()),
        qf(&|q| q.other_triangle.to_string()),
        qf(&|q| q.other_surface.to_string()),
        qf(&|q| q.wrong_pixels.to_string()),
        qf(&|q| (q.wrong_pixels as f64 / q.rays.max(1) as f64).to_string()),
        qf(&|q| q.diff_vs_default.to_string()),
        qf(&|q| q.t_rel_mean.to_string()),
        qf(&|q| q.t_rel_max.to_string()),
        qf(&|q| q.triangles.input.to_string()),
        qf(&|q| q.triangles.degenerate.to_string()),
        qf(&|q| q.triangles.clamped.to_string()),
        qf(&|q| q.triangles.stored.to_string()),
    ]);
    let c = r.cost.as_ref();
    rec.extend([
        opt(c.map(|c| c.div_latency.to_string())),
        opt(c.map(|c| c.isect_latency.to_string())),
        opt(c.map(|c| c.rom_bits.to_string())),
        opt(c.map(|c| c.dsp48e_est.to_string())),
        opt(c.map(|c| c.register_bits.to_string())),
    ]);
    let s = r.synth.as_ref();
    rec.extend([
        opt(s.map(|s| s.luts.to_string())),
        opt(s.map(|s| s.srl_luts.to_string())),
        opt(s.map(|s| s.ffs.to_string())),
        opt(s.map(|s| s.dsp48e.to_string())),
        opt(s.map(|s| s.bram18.to_string())),
        opt(r.core.as_ref().map(|k| k.cycles_per_ray.to_string())),
        opt(r.core.as_ref().map(|k| k.fill.to_string())),
        opt(r.core.as_ref().map(|k| k.max_stack_depth.to_string())),
        opt(r.core.as_ref().map(|k| k.mismatches.to_string())),
        if r.quality.is_some() { r.image_paths().0 } else { String::new() },
        opt(r.error.clone()),
        r.key.clone(),
    ]);
    rec
}

/// The last columns (image, error, key): the ECP5 columns of `--family ecp5` come before them.
const TAIL: usize = 3;

/// `fields` with `extra` inserted before the last `TAIL`.
fn with_extra(mut fields: Vec<String>, extra: Vec<String>) -> Vec<String> {
    let at = fields.len() - TAIL;
    fields.splice(at..at, extra);
    fields
}

/// The header of results.csv: `CSV_COLUMNS`, with `SHAPE_COLUMNS` and `CORE_COLUMNS` where the
/// sweep has them and `memory::csv_columns` and `pnr::csv_columns` before the last three.
pub fn csv_columns(spec: &SweepSpec) -> Vec<String> {
    let header = CSV_COLUMNS.iter().map(|c| c.to_string()).collect();
    let fields = with_optional(spec, header, SHAPE_COLUMNS.map(String::from), CORE_COLUMNS.map(String::from));
    let mut extra = super::memory::csv_columns(spec);
    extra.extend(super::pnr::csv_columns(spec));
    with_extra(fields, extra)
}

/// results.csv: a line per row under `csv_columns`.
pub fn csv_bytes(spec: &SweepSpec, rows: &[Row]) -> Vec<u8> {
    let mut w = csv::Writer::from_writer(Vec::new());
    // Writing into a Vec cannot fail.
    w.write_record(csv_columns(spec)).expect("csv into memory");
    for r in rows {
        let shape = [r.shape.slots, r.shape.units, r.shape.pipelines].map(|v| v.to_string());
        let k = r.core.as_ref();
        let core = [
            k.map(|k| k.rays_per_clock.to_string()).unwrap_or_default(),
            k.map(|k| k.triangle_tests_per_ray.to_string()).unwrap_or_default(),
            k.map(|k| k.node_steps_per_ray.to_string()).unwrap_or_default(),
            k.map(|k| k.slot_occupancy.to_string()).unwrap_or_default(),
        ];
        let fields = with_optional(spec, csv_record(r), shape, core);
        let mut extra = super::memory::csv_cells(spec, r.shape.memory, r.memory.as_ref());
        extra.extend(super::pnr::csv_cells(spec, &r.ecp5, r.mrays_per_s_at_fmax));
        w.write_record(with_extra(fields, extra)).expect("csv into memory");
    }
    w.into_inner().expect("csv into memory")
}

/// Stages results.json, results.csv and the images of every row (from the cache) into `files`.
pub fn add_tables_and_images(files: &mut OutputSet, dir: &Path, cache: &Path, results: &Results) -> Result<()> {
    // Rows that differ only in the core's shape share their images (the picture is the
    // model's): each is staged once.
    let mut staged = std::collections::BTreeSet::new();
    for r in results.rows.iter().filter(|r| r.quality.is_some()) {
        let (p, e) = r.image_paths();
        if !staged.insert(p.clone()) {
            continue;
        }
        let (png, errors) = cached_images(cache, &r.key)?;
        files.add(&dir.join(p), &png)?;
        files.add(&dir.join(e), &errors)?;
    }
    files.add(&dir.join("results.csv"), &csv_bytes(&results.spec, &results.rows))?;
    let mut json = serde_json::to_vec_pretty(results).expect("results serialise");
    json.push(b'\n');
    files.add(&dir.join("results.json"), &json)
}

/// Values as a comma-separated list, for the report's and the scripts' text.
pub(super) fn list<T: ToString>(v: &[T]) -> String {
    v.iter().map(T::to_string).collect::<Vec<_>>().join(", ")
}
