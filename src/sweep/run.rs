//! Running a sweep (or a shard of one) and merging shards.

use super::eval::{Extras, Row, SceneCtx, evaluate};
use super::output::{Results, add_tables_and_images, copy_cached, has_cached, load_cached, read_results, store_cached};
use super::pnr::Pnr;
use super::{Plan, Shard, SweepSpec, scene_labels};
use crate::error::{Error, Result};
use crate::fpga::ecp5::Tools;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

/// What a run did, for the summary line.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct RunSummary {
    pub computed: usize,
    pub cached: usize,
    pub failed: usize,
    /// Rays on which the simulated core disagreed with the golden model (`--core-sim`).
    pub mismatches: u64,
}

/// Loads and checks every scene of the sweep (before anything is written).
pub fn load_scenes(spec: &SweepSpec) -> Result<Vec<SceneCtx>> {
    let labels = scene_labels(&spec.scenes);
    let defaults = spec.defaults();
    spec.scenes
        .iter()
        .zip(labels)
        .map(|(s, l)| SceneCtx::load(s, l, &spec.camera, &defaults, &spec.leaf_size))
        .collect()
}

/// Evaluates this shard's configurations (those in the cache folder `cache` are read back)
/// and writes every output into `out`.
pub fn run(
    spec: &SweepSpec,
    plan: &Plan,
    scenes: &[SceneCtx],
    out: &Path,
    cache: &Path,
    shard: Option<Shard>,
    progress: bool,
) -> Result<RunSummary> {
    let mine: Vec<_> = plan.configs.iter().filter(|c| shard.is_none_or(|s| s.takes(c.index))).collect();
    let bar = if progress { indicatif::ProgressBar::new(mine.len() as u64) } else { indicatif::ProgressBar::hidden() };
    bar.set_style(
        indicatif::ProgressStyle::with_template("sweep [{bar:40}] {pos}/{len} configurations ({eta}) {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    // The ECP5 tools are checked before anything is written.
    let pnr = match &spec.ecp5 {
        Some(choice) if spec.synth => Some(Pnr {
            tools: Tools::require()?,
            choice: choice.clone(),
            target_mhz: spec.target_mhz,
            dir: out.join("synth"),
        }),
        _ => None,
    };
    let extras = Extras {
        synth_dir: spec.xc5v_synth().then(|| out.join("synth")),
        core_sim: spec.core_sim,
        target_mhz: spec.target_mhz,
        pnr,
        memory: spec.memory.clone(),
        device: spec.fitted_device(),
    };
    let results: Vec<Result<(Row, bool)>> = mine
        .par_iter()
        .map(|cfg| {
            let ctx = &scenes[cfg.scene];
            let key = ctx.key(&cfg.params, cfg.shape, spec);
            let done = match load_cached(cache, &key, cfg.index, &ctx.label) {
                // The key holds the shape; rows cached before it was swept do not.
                Some(row) => Ok((super::eval::Row { shape: cfg.shape, ..row }, true)),
                None => {
                    let e = evaluate(ctx, cfg, key, &extras);
                    store_cached(cache, &e).map(|()| (e.row, false))
                }
            };
            bar.inc(1);
            done
        })
        .collect();
    bar.finish_and_clear();
    let mut rows = Vec::with_capacity(results.len());
    let mut summary = RunSummary::default();
    for r in results {
        let (row, cached) = r?;
        summary.failed += row.error.is_some() as usize;
        summary.mismatches += row.core.as_ref().map_or(0, |k| k.mismatches);
        if cached {
            summary.cached += 1
        } else {
            summary.computed += 1
        }
        rows.push(row);
    }
    let results = Results {
        fxrt: env!("CARGO_PKG_VERSION").to_string(),
        spec: spec.clone(),
        configurations: plan.configs.len(),
        shard: shard.map(|s| s.to_string()),
        skipped: plan.skipped.clone(),
        rows,
    };
    write_all(out, cache, &results, plan)?;
    Ok(summary)
}

/// Every output of a sweep folder, from its results and cache alone, placed together (the
/// cache, filled as configurations finish, is not part of the set).
fn write_all(out: &Path, cache: &Path, results: &Results, plan: &Plan) -> Result<()> {
    let mut files = crate::io::OutputSet::new();
    add_tables_and_images(&mut files, out, cache, results)?;
    let grids = super::grid::add_grids(&mut files, out, cache, results, plan)?;
    let plots = super::plots::add_plots(&mut files, out, results, plan)?;
    super::report::add_report(&mut files, out, results, plan, &grids, &plots)?;
    files.commit()
}

/// Joins shard folders into `out`: the same spec everywhere, every configuration exactly once.
/// Each row's cache entry is taken from its shard's `cache` folder, else from `cache`, and
/// ends up in `cache` (default: `out/cache`).
pub fn merge(dirs: &[&Path], out: &Path, cache: Option<&Path>) -> Result<usize> {
    let mut first: Option<Results> = None;
    let mut rows: BTreeMap<usize, (Row, &Path)> = BTreeMap::new();
    for &dir in dirs {
        let r = read_results(dir)?;
        if let Some(f) = &first
            && (f.spec != r.spec || f.fxrt != r.fxrt)
        {
            return Err(Error::file(
                dir,
                "is a different sweep (its spec or fxrt version differs from the first folder's)",
            ));
        }
        for row in &r.rows {
            if rows.insert(row.index, (row.clone(), dir)).is_some() {
                return Err(Error::file(dir, format!("configuration {} is in two of the merged folders", row.index)));
            }
        }
        first.get_or_insert(r);
    }
    let Some(first) = first else { return Err(Error::new("sweep merge", "no folders to merge")) };
    let plan = first.spec.plan()?;
    let missing: Vec<String> =
        (0..plan.configs.len()).filter(|i| !rows.contains_key(i)).take(8).map(|i| i.to_string()).collect();
    if !missing.is_empty() {
        return Err(Error::new(
            "sweep merge",
            format!("configurations {} … are in none of the folders: is a shard missing?", missing.join(", ")),
        ));
    }
    let target = cache.map(Path::to_path_buf).unwrap_or_else(|| out.join("cache"));
    for (row, dir) in rows.values() {
        let own = dir.join("cache");
        let source = if has_cached(&own, &row.key) { own } else { target.clone() };
        if !has_cached(&source, &row.key) {
            return Err(Error::file(dir, format!("configuration {} has no cache entry: pass --cache", row.index)));
        }
        if std::path::absolute(&source).ok() != std::path::absolute(&target).ok() {
            copy_cached(&source, &target, &row.key)?;
        }
    }
    let results = Results { shard: None, rows: rows.into_values().map(|(r, _)| r).collect(), ..first };
    write_all(out, &target, &results, &plan)?;
    Ok(results.rows.len())
}
