//! Bad input that used to hang, or pass as garbage, or fail under another name (issue 27):
//! each is refused with exit code 2 and one line naming the file or parameter at fault, before
//! anything is written.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs fxrt, failing the test (not hanging it) if it runs for more than a minute.
fn fxrt(args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_fxrt"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("fxrt runs");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("fxrt {args:?} ran for a minute: it hangs");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Exit 2, one line starting with `subject` (after the `fxrt: ` prefix) and containing
/// `want`, no panic, and `out` not created.
fn refused(args: &[&str], subject: &str, want: &str, out: &Path) {
    let o = fxrt(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    assert!(err.starts_with(&format!("fxrt: {subject}")), "{args:?}: {err:?} should name {subject}");
    assert!(err.contains(want), "{args:?}: {err:?} should say {want:?}");
    assert!(!err.contains("panicked"));
    assert!(!out.exists(), "{args:?} left {} behind", out.display());
}

/// Sets `fields` of word `k` of a `.hex` ROM (words of at most 128 bits) in place, with the
/// field positions scene.json gives.
fn edit_word(dir: &Path, rom: &str, k: usize, fields: &[(&str, u128)]) {
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("scene.json")).unwrap()).unwrap();
    let layout = json["roms"].as_array().unwrap().iter().find(|r| r["rom"] == rom).unwrap();
    let path = dir.join(format!("{rom}.hex"));
    let mut lines: Vec<String> = std::fs::read_to_string(&path).unwrap().lines().map(String::from).collect();
    let line = &mut lines[k + 1];
    let mut w = u128::from_str_radix(line, 16).unwrap();
    for &(name, v) in fields {
        let f = layout["fields"].as_array().unwrap().iter().find(|f| f["name"] == name).unwrap();
        let (lsb, width) = (f["lsb"].as_u64().unwrap(), f["width"].as_u64().unwrap());
        let mask = ((1u128 << width) - 1) << lsb;
        w = (w & !mask) | ((v << lsb) & mask);
    }
    *line = format!("{w:0digits$x}", digits = line.len());
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
}

/// `gen --scene DIR` used to write HDL for a node that is its own child, a leaf running past
/// the leaf table and a leaf naming a missing triangle, and to hang (a 4-Gbit signal) on a
/// count width of 2^32 − 1 in scene.json.
#[test]
fn gen_refuses_scene_images_that_are_not_fxrts() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let written = d.join("written");
    let o = fxrt(&["scene", "--builtin", "thin", "--n", "16", "--m", "16", "--out", written.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // thin: 5 triangles, node 0 inner over the leaves 1 and 2.
    type Edit = Box<dyn Fn(&Path)>;
    let cases: Vec<(&str, Edit, &str, &str)> = vec![
        (
            "count",
            Box::new(|s: &Path| {
                let p = s.join("scene.json");
                let text = std::fs::read_to_string(&p).unwrap();
                let mut j: serde_json::Value = serde_json::from_str(&text).unwrap();
                let node = j["roms"].as_array_mut().unwrap().iter_mut().find(|r| r["rom"] == "node").unwrap();
                let count = node["fields"].as_array_mut().unwrap().iter_mut().find(|f| f["name"] == "count").unwrap();
                count["width"] = 4294967295u32.into();
                std::fs::write(p, serde_json::to_vec(&j).unwrap()).unwrap();
            }),
            "scene.json: ",
            "the node ROM's count field is 4294967295 bits",
        ),
        (
            "self",
            Box::new(|s: &Path| edit_word(s, "node", 0, &[("child", 0)])),
            "node.hex:2: ",
            "inner node 0: its children 0 and 1",
        ),
        (
            "beyond",
            Box::new(|s: &Path| edit_word(s, "node", 1, &[("first", 4)])),
            "node.hex:3: ",
            "run beyond the 5 of the leaf table",
        ),
        (
            "missing",
            Box::new(|s: &Path| edit_word(s, "leaf", 2, &[("tri", 7)])),
            "leaf.hex:4: ",
            "triangle 7 is not in the table of 5",
        ),
    ];
    for (name, edit, file, want) in cases {
        let scene = d.join(name);
        std::fs::create_dir(&scene).unwrap();
        for f in ["scene.json", "tri.hex", "node.hex", "leaf.hex"] {
            std::fs::copy(written.join(f), scene.join(f)).unwrap();
        }
        edit(&scene);
        let out = d.join(format!("{name}-hdl"));
        let subject = format!("{}/{file}", scene.display());
        refused(&["gen", "--scene", scene.to_str().unwrap(), "--out", out.to_str().unwrap()], &subject, want, &out);
    }
}

/// Coordinates too large and extents too small to scale name the OBJ file and the cause (not
/// --eye, --at or "no extent"), in every command that loads a scene.
#[test]
fn scenes_beyond_the_coordinate_limits_name_their_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases = [
        ("big.obj", "v -1e300 0 0\nv 1e300 0 0\nv 0 1e300 0\nf 1 2 3\n", "coordinates too large"),
        ("huge.obj", "v -1.7e308 0 0\nv 1.7e308 0 0\nv 0 1 0\nf 1 2 3\n", "coordinates too large"),
        ("tiny.obj", "v 0 0 0\nv 1e-310 0 0\nv 0 1e-310 0\nf 1 2 3\n", "extent 1e-310 is too small to scale"),
    ];
    let (png, rom) = (d.join("out.png"), d.join("rom"));
    for (name, text, want) in cases {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        let p = p.to_str().unwrap();
        refused(&["render", p, "--size", "8x8", "--png", png.to_str().unwrap()], p, want, &png);
        refused(&["scene", p, "--out", rom.to_str().unwrap()], p, want, &rom);
    }
}

/// Above `Params::max_edge_shift` (65 at n 29, m 32) edge quantisation wrapped: `scene` said
/// "0 clamped" and `render` lost its hits.
#[test]
fn an_edge_shift_above_the_limit_names_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let (png, rom, sw) = (dir.path().join("out.png"), dir.path().join("rom"), dir.path().join("sw"));
    let want = "is above 65, the largest E for --n 29 --m 32";
    refused(
        &["scene", "--builtin", "thin", "--edge-shift", "120", "--out", rom.to_str().unwrap()],
        "--edge-shift: 120 ",
        want,
        &rom,
    );
    refused(
        &["render", "--builtin", "thin", "--edge-shift", "66", "--png", png.to_str().unwrap()],
        "--edge-shift: 66 ",
        want,
        &png,
    );
    let want = "is above 84, the largest E for --n 10 --m 32";
    refused(
        &["render", "--builtin", "thin", "--n", "10", "--edge-shift", "85", "--png", png.to_str().unwrap()],
        "--edge-shift: 85 ",
        want,
        &png,
    );
    refused(
        &["sweep", "--builtin", "thin", "--edge-shift", "93", "--out", sw.to_str().unwrap()],
        "sweep: ",
        "--edge-shift: 93 is above 65",
        &sw,
    );
    // The largest E is accepted.
    let o = fxrt(&["scene", "--builtin", "thin", "--edge-shift", "65", "--out", rom.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// An external-memory core's options out of range, contradictory, or caches that do not fit
/// the block RAM: exit 2 naming the option, no picture written.
#[test]
fn external_memory_options_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let p = png.to_str().unwrap();
    let sim = |extra: &[&'static str]| -> Vec<String> {
        let mut v: Vec<String> = ["sim", "--builtin", "cornell", "--size", "8x8", "--memory", "external", "--png", p]
            .map(String::from)
            .to_vec();
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    for (extra, subject, want) in [
        (&["--node-cache-kb", "3"][..], "node-cache-kb", "power of two"),
        (&["--tri-cache-kb", "0"][..], "tri-cache-kb", "power of two"),
        (&["--cache-ways", "3"][..], "cache-ways", "1, 2, 4"),
        (&["--mem-latency", "0"][..], "mem-latency", "from 1"),
        (&["--mem-pauses", "256"][..], "mem-pauses", "at most 255"),
        (&["--cache-line", "96"][..], "cache-line", "power of two"),
        (&["--mem-bits", "48"][..], "mem-bits", "32, 64, 128"),
        (&["--tri-cache-kb", "1024", "--bram-kbits", "4000"][..], "bram-kbits", "caches"),
        (&["--raygen", "--eye", "0,1,0", "--at", "1,1,0"][..], "memory", "host rays"),
        (&["--ray-order", "tiles", "--shuffle-seed", "3"][..], "ray-order", "shuffle"),
    ] {
        let args = sim(extra);
        let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        refused(&args, &format!("--{subject}"), want, &png);
    }
}

/// `fxrt test` runs one intersection pipeline: a core shape (a device to fit, slots, units,
/// pipelines) would be ignored, so it is refused, naming the option; the build folder is not
/// made.
#[test]
fn test_refuses_a_core_shape() {
    let dir = tempfile::tempdir().unwrap();
    let build = dir.path().join("build");
    let b = build.to_str().unwrap();
    for (extra, subject) in [
        (&["--device", "lfe5u-85f"][..], "device"),
        (&["--pipelines", "2", "--units", "2"][..], "pipelines"),
        (&["--slots", "8"][..], "slots"),
        (&["--units", "4"][..], "units"),
    ] {
        let mut args = vec!["test", "--builtin", "cornell", "--vectors", "10", "--build", b];
        args.extend_from_slice(extra);
        refused(&args, &format!("--{subject}"), "intersection pipeline alone", &build);
    }
}
