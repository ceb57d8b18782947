//! Helpers shared by the integration tests.
#![allow(dead_code)]

use fxrt::params::Params;
use fxrt::scene::builtin::BUILTIN_NAMES;
use fxrt::scene::{Scene, SceneSource};
use std::path::PathBuf;

/// `../shared/scenes` beside the checkout, when it is there.
pub fn shared_scenes() -> Option<Vec<PathBuf>> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/scenes");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    v.sort();
    Some(v)
}

/// Every built-in scene, plus every shared OBJ (or a note that they were skipped).
pub fn all_scenes(params: &Params) -> Vec<Scene> {
    let mut out: Vec<Scene> =
        BUILTIN_NAMES.iter().map(|n| Scene::load(&SceneSource::Builtin(n.to_string()), params).unwrap()).collect();
    match shared_scenes() {
        Some(paths) => out.extend(paths.into_iter().map(|p| Scene::load(&SceneSource::Obj(p), params).unwrap())),
        None => say("skipped: ../shared/scenes is not there; only built-in scenes were tested"),
    }
    out
}

/// A line on the real stderr, past the test harness's capture, so a skip is always visible.
pub fn say(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// The rows of a sweep folder's results.csv, each a map from column to cell.
pub fn sweep_rows(dir: &std::path::Path) -> Vec<std::collections::BTreeMap<String, String>> {
    let mut r = csv::Reader::from_path(dir.join("results.csv")).unwrap();
    let headers = r.headers().unwrap().clone();
    r.records()
        .map(|rec| headers.iter().map(String::from).zip(rec.unwrap().iter().map(String::from)).collect())
        .collect()
}
