//! The bodies of the fuzz targets in `fuzz/` (cargo fuzz; docs/FUZZING.md), in the library so
//! that `cargo test` runs every committed corpus file through the same code
//! (tests/fuzz_corpus.rs) without libFuzzer. Each takes arbitrary bytes and returns Ok or a
//! clean `Error` — what the command line turns into exit code 2 and one line. It panics only
//! where the project promises something the input broke (a panic, an overflow in a debug
//! build, or the fast paths disagreeing with the golden model), which is what the fuzzer is to
//! report.

use crate::cores::top::{CoreParams, core_module};
use crate::error::Result;
use crate::model::golden::{Golden, GridRay};
use crate::model::ray::{WorldRay, normalize, quantize_direction, quantize_ray};
use crate::params::{EdgeShift, Params, TreeSplit};
use crate::render::fast::{FastGolden, LANES};
use crate::scene::images::SceneRoms;
use crate::scene::{Scene, Tri, obj, report, rom};
use std::path::Path;

/// The fuzz targets, by name: what `fuzz/fuzz_targets/<name>.rs` calls and what
/// fuzz/corpus/<name>/ seeds.
pub const TARGETS: [&str; 3] = ["obj", "tris", "rom"];

/// Runs the body of fuzz target `target` on `data`; `dir` is a scratch directory for `rom`.
pub fn run(target: &str, data: &[u8], dir: &Path) -> Result<()> {
    match target {
        "obj" => obj(data),
        "tris" => tris(data),
        "rom" => rom(dir, data),
        _ => panic!("no fuzz target '{target}': the targets are {TARGETS:?}"),
    }
}

/// A scratch directory for this process's `rom` inputs, under the system's temporary
/// directory (the fuzz script points TMPDIR into fuzz/work/ and removes it afterwards).
pub fn scratch_dir() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("fxrt-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch directory can be made");
    dir
}

/// Bytes taken from the front of the input for the parameters (`params_from`).
pub const PARAM_BYTES: usize = 8;

/// A parameter set from eight bytes, each mapped into its parameter's whole range
/// (`params::RANGES`), so cross-parameter limits are fuzzed too (`validate` refuses what breaks
/// them): n, m, t, c, edge shift (high bit: auto), leaf size, tree split (low bit: SAH), stack
/// depth; the tree byte's other bits, with the SAH, the step price (`sah_step_percent`: 40 per
/// step of the seven bits). Missing bytes are zero.
pub fn params_from(bytes: &[u8]) -> Params {
    let b = |i: usize| bytes.get(i).copied().unwrap_or(0) as u32;
    Params {
        n: 4 + b(0) % 37,
        m: 8 + b(1) % 57,
        t: b(2) % 63,
        c: b(3) % 65,
        edge_shift: if b(4) >= 128 { EdgeShift::Auto } else { EdgeShift::Fixed(b(4) % 121) },
        leaf_size: 1 + b(5) % 64,
        tree: if b(6) & 1 == 1 { TreeSplit::Sah } else { TreeSplit::Middle },
        stack_depth: 1 + b(7),
        sah_step_percent: if b(6) & 1 == 1 { (b(6) >> 1) * 40 } else { 0 },
    }
}

fn split_params(data: &[u8]) -> (Params, &[u8]) {
    let k = data.len().min(PARAM_BYTES);
    (params_from(&data[..k]), &data[k..])
}

/// `obj`: eight parameter bytes, then the text of an OBJ file, through what `fxrt scene` does:
/// load, build, the ROM words and scene.json.
pub fn obj(data: &[u8]) -> Result<()> {
    let (params, text) = split_params(data);
    let path = Path::new("fuzz.obj");
    let tris = obj::parse_obj(path, text)?;
    let scene = Scene::build("fuzz.obj", tris, &params)?;
    let roms = rom::words(&scene);
    report::scene_json(&scene, &roms);
    report::stats_text(&scene);
    Ok(())
}

/// `tris`: eight parameter bytes, a format byte (low bit: f32, else f64; the rest: 1 to 16
/// triangles), the triangles' coordinates as raw little-endian floats (any bit pattern), and
/// what is left as rays. A scene that builds traces every ray through the golden model, its
/// early-out walk and the fast paths (`FastGolden`), which must agree bit for bit.
pub fn tris(data: &[u8]) -> Result<()> {
    let (params, rest) = split_params(data);
    let Some((&format, rest)) = rest.split_first() else { return Ok(()) };
    let (size, count) = (if format & 1 == 1 { 4 } else { 8 }, 1 + (format >> 1) as usize % 16);
    let take = (9 * size * count).min(rest.len() / (9 * size) * 9 * size);
    let (floats, rays) = rest.split_at(take);
    let values: Vec<f64> = floats
        .chunks_exact(size)
        .map(|c| match c.try_into() {
            Ok(b4) => f32::from_le_bytes(b4) as f64,
            Err(_) => f64::from_le_bytes(c.try_into().expect("eight bytes")),
        })
        .collect();
    let world: Vec<Tri> =
        values.chunks_exact(9).map(|v| std::array::from_fn(|i| [v[3 * i], v[3 * i + 1], v[3 * i + 2]])).collect();
    let scene = Scene::build("fuzz", world, &params)?;
    rom::words(&scene);
    trace_all(&scene, &grid_rays(&scene, rays));
    Ok(())
}

/// Rays from 24-byte records: a grid origin (three u32 taken modulo the box) and a direction
/// (three i32 scaled to m bits), and the same bytes read as a world ray through the scene's
/// quantisation (origin on the scene's box, direction normalised).
fn grid_rays(scene: &Scene, bytes: &[u8]) -> Vec<GridRay> {
    let g = Golden::new(scene);
    let mut rays = Vec::new();
    for r in bytes.chunks_exact(24).take(2 * LANES) {
        let word = |i: usize| u32::from_le_bytes(r[4 * i..4 * i + 4].try_into().expect("four bytes"));
        let o: [i64; 3] = std::array::from_fn(|k| word(k) as i64 % (scene.grid_box.hi[k] + 1));
        let d: [f64; 3] = std::array::from_fn(|k| word(3 + k) as i32 as f64);
        if d == [0.0; 3] {
            continue;
        }
        let w = quantize_direction(normalize(d), g.f);
        if w != [0; 3] {
            rays.push(g.ray(o, w));
        }
        let world = WorldRay { o: scene.transform.to_world(o.map(|x| x as f64 * 1.5 - 0.25)), d: normalize(d) };
        rays.extend(quantize_ray(scene, &g, &world).map(|q| q.ray));
    }
    rays
}

/// Every path of the golden model gives the same closest hit for each ray.
fn trace_all(scene: &Scene, rays: &[GridRay]) {
    let fast = FastGolden::new(scene);
    let g = &fast.golden;
    let want: Vec<_> = rays.iter().map(|r| g.trace(scene, r).0).collect();
    for (r, w) in rays.iter().zip(&want) {
        assert_eq!(g.trace_culled(scene, r).0, *w, "trace_culled differs from trace: {r:?}");
        assert_eq!(fast.trace(r).0, *w, "FastGolden::trace differs from trace: {r:?}");
    }
    if fast.kernel().is_some() {
        let (fit, want): (Vec<GridRay>, Vec<_>) = rays.iter().zip(want).filter(|(r, _)| fast.fits(r)).unzip();
        for (chunk, w) in fit.chunks(LANES).zip(want.chunks(LANES)) {
            assert_eq!(&fast.trace_packet(chunk)[..chunk.len()], w, "the packet path differs from trace: {chunk:?}");
        }
    }
}

/// The marker line between the files of a `rom` input.
pub const ROM_SEPARATOR: &[u8] = b"\n====\n";

/// The files of a `rom` input, in this order, separated by `ROM_SEPARATOR`.
pub const ROM_FILES: [&str; 4] = ["scene.json", "tri.hex", "node.hex", "leaf.hex"];

/// `rom`: scene.json, tri.hex, node.hex and leaf.hex separated by `ROM_SEPARATOR` lines (a
/// missing part is a missing file), written into `dir` and loaded as `fxrt gen --scene` does;
/// an image that loads must build the core's netlist (one unit, one slot) and read back the
/// same after being written again.
pub fn rom(dir: &Path, data: &[u8]) -> Result<()> {
    let mut parts = split(data, ROM_SEPARATOR);
    parts.resize(ROM_FILES.len(), None);
    for (name, part) in ROM_FILES.iter().zip(&parts) {
        let path = dir.join(name);
        match part {
            Some(bytes) => std::fs::write(&path, bytes).expect("the fuzz directory is writable"),
            None => {
                let _ = std::fs::remove_file(&path);
            }
        }
    }
    let roms = SceneRoms::load(dir)?;
    let p = CoreParams::shaped(&roms, &crate::cores::top::CoreSpec { slots: 1, units: 1, ..Default::default() });
    p.check()?;
    // The netlist's structure depends on the image only through its parameters, edge shift
    // and layouts (the words are constants in it); building and printing a core costs some
    // 50 ms, so each shape is built once per process, and the fuzzer spends its time on the
    // loader.
    static SHAPES: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
    let shape = format!("{:?} {} {:?} {:?} {:?}", roms.params, roms.edge_shift, roms.tri.0, roms.node.0, roms.leaf.0);
    let mut shapes = SHAPES.lock().unwrap_or_else(|e| e.into_inner());
    if !shapes.contains(&shape) {
        shapes.push(shape);
        crate::rtl::emit::design_files(&core_module(&p, &roms), "v");
    }
    drop(shapes);
    for (layout, words) in [&roms.tri, &roms.node, &roms.leaf] {
        std::fs::write(dir.join(format!("{}.hex", layout.rom)), rom::readmemh(layout, words)).expect("writable");
    }
    let again = SceneRoms::load(dir).expect("an image fxrt wrote loads");
    assert_eq!(again.hash(), roms.hash(), "the image read back differs");
    Ok(())
}

/// The parts of `data` between occurrences of `sep` (at most four).
fn split<'a>(data: &'a [u8], sep: &[u8]) -> Vec<Option<&'a [u8]>> {
    let mut parts = Vec::new();
    let mut rest = data;
    while parts.len() + 1 < ROM_FILES.len() {
        let Some(i) = rest.windows(sep.len()).position(|w| w == sep) else { break };
        parts.push(Some(&rest[..i]));
        rest = &rest[i + sep.len()..];
    }
    parts.push(Some(rest));
    parts
}
