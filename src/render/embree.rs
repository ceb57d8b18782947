//! Embree's side of `fxrt bench --against-embree`: the scene's triangles and a camera's pixel
//! rays written as little-endian binary files, traced by `scripts/embree_bench.py` (the Python
//! package embreex, Embree 4, which `scripts/install-deps.sh` puts in the project's `.venv`)
//! in a subprocess, and its JSON line read back.
//!
//! Files (numpy reads each with `fromfile`):
//! - `triangles.f32`: T × 3 × 3 f32, the input triangles in world coordinates in file order
//!   (`Scene::world` rounded to f32, as the f32 reference rounds them), so Embree's primitive
//!   number is the input triangle number;
//! - `origins.f64`, `directions.f64`: N × 3 f64, each pixel ray of `Camera::pixel_rays` in
//!   pixel order, exactly the rays the golden model quantises (Embree rounds them to f32).

use crate::error::{Error, Result};
use crate::model::camera::Camera;
use crate::scene::Scene;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The script, carried in the binary so `fxrt` needs no source tree beside it.
const SCRIPT: &str = include_str!("../../scripts/embree_bench.py");

/// The script's exit code when embreex cannot be imported.
const NO_EMBREEX: i32 = 3;

/// What the script measured.
#[derive(Clone, Debug, Deserialize, PartialEq)]
pub struct EmbreeReport {
    /// Embree's version (e.g. 4.4.0).
    pub embree: String,
    /// embreex's version.
    pub embreex: String,
    pub rays: u64,
    pub triangles: u64,
    pub hits: u64,
    pub runs: Vec<EmbreeRun>,
}

/// The best time of one thread count.
#[derive(Clone, Debug, Deserialize, PartialEq)]
pub struct EmbreeRun {
    pub threads: usize,
    pub seconds: f64,
    pub mrays_per_s: f64,
}

impl EmbreeReport {
    /// Mrays/s with `threads` threads, if that count ran.
    pub fn mrays_per_s(&self, threads: usize) -> Option<f64> {
        self.runs.iter().find(|r| r.threads == threads).map(|r| r.mrays_per_s)
    }
}

/// `triangles.f32`: every input triangle, three vertices of x, y, z, as f32.
pub fn triangle_bytes(scene: &Scene) -> Vec<u8> {
    scene.world.iter().flatten().flatten().flat_map(|&x| (x as f32).to_le_bytes()).collect()
}

/// `origins.f64` and `directions.f64`: every pixel ray of `cam`, row-major, top row first.
pub fn ray_bytes(cam: &Camera) -> (Vec<u8>, Vec<u8>) {
    let rays = cam.pixel_rays();
    let n = cam.width as usize * cam.height as usize * 24;
    let (mut origins, mut dirs) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for py in 0..cam.height {
        for px in 0..cam.width {
            let r = rays.ray(px, py);
            origins.extend(r.o.iter().flat_map(|x| x.to_le_bytes()));
            dirs.extend(r.d.iter().flat_map(|x| x.to_le_bytes()));
        }
    }
    (origins, dirs)
}

/// The Python that runs the script: `$FXRT_PYTHON` when set (only it), else `./.venv`, the
/// source tree's `.venv`, or `python3` on the PATH — the first that imports embreex.
pub fn python() -> Option<PathBuf> {
    let candidates = match std::env::var_os("FXRT_PYTHON") {
        Some(p) => vec![PathBuf::from(p)],
        None => {
            crate::io::venv_bins().into_iter().map(|d| d.join("python")).chain([PathBuf::from("python3")]).collect()
        }
    };
    let imports =
        |p: &PathBuf| Command::new(p).args(["-c", "import embreex, numpy"]).output().is_ok_and(|o| o.status.success());
    candidates.into_iter().find(imports)
}

fn missing() -> Error {
    let place = match std::env::var_os("FXRT_PYTHON") {
        Some(p) => format!("$FXRT_PYTHON ({}) cannot import it", Path::new(&p).display()),
        None => "not found in .venv nor for python3".to_string(),
    };
    Error::param(
        "against-embree",
        format!(
            "needs the Python package embreex (Embree 4), {place}: run scripts/install-deps.sh (it puts embreex into .venv)"
        ),
    )
}

/// The Python with embreex, or the error naming `--against-embree` (exit 2).
pub fn require() -> Result<PathBuf> {
    python().ok_or_else(missing)
}

/// Writes the scene and `cam`'s rays into `dir` and traces them in Embree with each of
/// `threads`, best of `repeat`.
pub fn measure(
    python: &Path,
    dir: &Path,
    scene: &Scene,
    cam: &Camera,
    threads: &[usize],
    repeat: u32,
) -> Result<EmbreeReport> {
    let (origins, dirs) = ray_bytes(cam);
    let script = dir.join("embree_bench.py");
    let mut files = crate::io::OutputSet::new();
    files.add(&script, SCRIPT.as_bytes())?;
    files.add(&dir.join("triangles.f32"), &triangle_bytes(scene))?;
    files.add(&dir.join("origins.f64"), &origins)?;
    files.add(&dir.join("directions.f64"), &dirs)?;
    files.commit()?;
    let counts: Vec<String> = threads.iter().map(|t| t.to_string()).collect();
    let out = Command::new(python)
        .arg(&script)
        .arg(dir)
        .args(["--threads", &counts.join(","), "--repeat", &repeat.to_string(), "--width", &cam.width.to_string()])
        .output()
        .map_err(|e| Error::file(python, format!("cannot run: {e}")))?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.status.code() == Some(NO_EMBREEX) {
        return Err(missing());
    }
    let last = |s: &str| s.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("no output").to_string();
    if !out.status.success() {
        return Err(Error::file(&script, format!("failed ({}): {}", out.status, last(&stderr))));
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(&last(&stdout))
        .map_err(|e| Error::file(&script, format!("unexpected output ({e}): {}", last(&stdout))))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::scene::SceneSource;

    fn f32s(b: &[u8]) -> Vec<f32> {
        b.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect()
    }

    fn f64s(b: &[u8]) -> Vec<f64> {
        b.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect()
    }

    /// The files read back give every triangle's vertices (as f32) in file order and every
    /// pixel's ray bit for bit, in pixel order.
    #[test]
    fn triangles_and_rays_read_back_exactly() {
        let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
        let tris = f32s(&triangle_bytes(&scene));
        assert_eq!(tris.len(), scene.world.len() * 9);
        for (t, back) in scene.world.iter().zip(tris.chunks_exact(9)) {
            let want: Vec<f32> = t.iter().flatten().map(|&x| x as f32).collect();
            assert_eq!(back, &want[..]);
        }
        let cam = Camera::default_for(&scene, 7, 5);
        let (o, d) = ray_bytes(&cam);
        let (o, d) = (f64s(&o), f64s(&d));
        assert_eq!((o.len(), d.len()), (7 * 5 * 3, 7 * 5 * 3));
        for (i, (o, d)) in o.chunks_exact(3).zip(d.chunks_exact(3)).enumerate() {
            let r = cam.ray(i as u32 % 7, i as u32 / 7);
            assert_eq!((o, d), (&r.o[..], &r.d[..]), "pixel {i}");
        }
    }

    #[test]
    fn the_report_line_parses() {
        let line = r#"{"embree": "4.4.0", "embreex": "4.4.0.post1", "rays": 4, "triangles": 2, "hits": 1,
            "runs": [{"threads": 1, "seconds": 0.5, "mrays_per_s": 8e-6}, {"threads": 2, "seconds": 0.25, "mrays_per_s": 1.6e-5}]}"#;
        let r: EmbreeReport = serde_json::from_str(line).unwrap();
        assert_eq!((r.hits, r.mrays_per_s(2), r.mrays_per_s(3)), (1, Some(1.6e-5), None));
    }
}
