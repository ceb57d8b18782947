//! The command line as a user meets it: outputs, determinism and bad input.

use std::path::Path;
use std::process::{Command, Output};

fn fxrt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fxrt")).args(args).output().expect("fxrt runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn render_writes_ids_and_depth_of_the_documented_size() {
    let dir = tempfile::tempdir().unwrap();
    let (ids, depth, png) = (dir.path().join("i.bin"), dir.path().join("d.bin"), dir.path().join("p.png"));
    let o = fxrt(&[
        "render",
        "--builtin",
        "cornell",
        "--size",
        "40x30",
        "--ids",
        ids.to_str().unwrap(),
        "--depth",
        depth.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
        "--shade",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let line = String::from_utf8_lossy(&o.stdout);
    assert!(line.starts_with("rays: ") && line.contains("Mrays/s"), "{line}");
    let ids = std::fs::read(&ids).unwrap();
    let depth = std::fs::read(&depth).unwrap();
    assert_eq!(ids.len(), 40 * 30 * 4);
    assert_eq!(depth.len(), 40 * 30 * 4);
    let ids: Vec<i32> = ids.chunks(4).map(|c| i32::from_le_bytes(c.try_into().unwrap())).collect();
    let depth: Vec<f32> = depth.chunks(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
    // The framing camera sees the box: hits have finite depth, misses +inf.
    assert!(ids.iter().filter(|&&i| i >= 0).count() > 600);
    for (i, d) in ids.iter().zip(&depth) {
        assert_eq!(*i < 0, d.is_infinite());
        assert!(*i < 32);
    }
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
}

#[test]
fn scene_output_is_complete_and_byte_identical_across_runs() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for d in [&a, &b] {
        let o = fxrt(&[
            "scene",
            "--builtin",
            "random",
            "--out",
            d.path().to_str().unwrap(),
            "--n",
            "23",
            "--m",
            "27",
            "--stats",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(String::from_utf8_lossy(&o.stdout).contains("edge components"));
    }
    let mut names: Vec<String> =
        std::fs::read_dir(a.path()).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    let want = [
        "fxrt_scene.h",
        "fxrt_scene_pkg.vhd",
        "leaf.coe",
        "leaf.hex",
        "leaf.mem",
        "node.coe",
        "node.hex",
        "node.mem",
        "scene.bin",
        "scene.json",
        "tri.coe",
        "tri.hex",
        "tri.mem",
    ];
    assert_eq!(names, want);
    for n in want {
        assert_eq!(
            std::fs::read(a.path().join(n)).unwrap(),
            std::fs::read(b.path().join(n)).unwrap(),
            "{n} differs between runs"
        );
    }
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(a.path().join("scene.json")).unwrap()).unwrap();
    assert_eq!(json["triangles"]["input"], 2000);
    assert_eq!(json["params"]["n"], 23);
    let tri_hex = std::fs::read_to_string(a.path().join("tri.hex")).unwrap();
    let words: Vec<&str> = tri_hex.lines().filter(|l| !l.starts_with("//")).collect();
    assert_eq!(words.len() as u64, json["triangles"]["stored"].as_u64().unwrap());
    assert!(words.iter().all(|w| w.len() == (2 + 3 * 23 + 3 + 6 * 27usize).div_ceil(4)));
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p.to_str().unwrap().to_string()
}

/// Exit 2, one line naming the subject, and no output file left behind.
fn assert_rejected(args: &[&str], subject: &str, out: &Path) {
    let o = fxrt(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    assert!(err.contains(subject), "{args:?}: {err:?} should name {subject}");
    assert!(!err.contains("panicked"));
    assert!(!out.exists(), "{args:?} left {} behind", out.display());
}

#[test]
fn bad_input_is_exit_2_with_one_line_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let png = d.join("out.png");
    let png_s = png.to_str().unwrap();
    let cases: &[(&str, &[u8])] = &[
        ("malformed.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n"),
        ("binary.obj", b"v 0 0 0\n\xff\xfe\x00\x01\nf 1 2 3\n"),
        ("nan.obj", b"v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"),
        ("inf.obj", b"v 0 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\n"),
        ("range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
        ("negative.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n"),
        ("noface.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
        ("point.obj", b"v 1 2 3\n"),
        ("degenerate.obj", b"v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\nf 1 1 2\n"),
        ("empty.obj", b""),
    ];
    for (name, text) in cases {
        let p = write(d, name, text);
        assert_rejected(&["render", &p, "--png", png_s], &p, &png);
        assert_rejected(&["scene", &p, "--out", d.join("rom").to_str().unwrap()], &p, &d.join("rom"));
    }
    assert_rejected(&["render", &d.join("missing.obj").to_string_lossy(), "--png", png_s], "missing.obj", &png);
    assert_rejected(&["render", "--builtin", "teapot", "--n", "41", "--png", png_s], "--n: 41", &png);
    assert_rejected(&["render", "--builtin", "teapot", "--t", "31", "--png", png_s], "--t", &png);
    assert_rejected(&["render", "--builtin", "teapot", "--m", "64", "--n", "40", "--png", png_s], "--m", &png);
    assert_rejected(&["render", "--builtin", "nosuch", "--png", png_s], "--builtin", &png);
    assert_rejected(
        &["render", "--builtin", "teapot", "--eye", "0,0,0", "--at", "0,0,0", "--png", png_s],
        "--at",
        &png,
    );
    assert_rejected(&["render", "--builtin", "teapot", "--threads", "0", "--png", png_s], "--threads", &png);
    assert_rejected(&["render", "--builtin", "teapot", "--size", "0x4", "--png", png_s], "--size", &png);
    assert_rejected(&["render", "--builtin", "teapot", "--edge-shift", "-3", "--png", png_s], "--edge-shift", &png);
    assert_rejected(&["render", "--builtin", "teapot", "--eye", "1,2", "--png", png_s], "--eye", &png);
}

#[test]
fn a_bad_obj_is_rejected_with_its_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let png = d.join("out.png");
    let png_s = png.to_str().unwrap();
    let head = "# a scan\n\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let cases = [
        ("coord.obj", format!("{head}v 1 abc 0\nf 1 2 4\n"), 7, "'abc'"),
        ("index.obj", format!("{head}f 1 2 3\nf 1 2 9\n"), 8, "'9'"),
        ("nan.obj", format!("{head}v nan 0 0\nf 1 2 4\n"), 7, "non-finite"),
    ];
    for (name, text, line, token) in cases {
        let p = write(d, name, text.as_bytes());
        let at = format!("{p}:{line}: ");
        assert_rejected(&["render", &p, "--png", png_s], &at, &png);
        let err = stderr(&fxrt(&["render", &p, "--png", png_s]));
        assert!(err.contains(token), "{err:?} should contain {token:?}");
    }
}

#[test]
fn gen_rejects_widths_the_rtl_layer_cannot_hold_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("hdl");
    // 2n + m = 124 is a valid model, but ω·np would need 2m + 1 = 129 bits.
    let o = fxrt(&["gen", "--builtin", "random", "--n", "30", "--m", "64", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--m") && stderr(&o).contains("128"), "{}", stderr(&o));
    assert!(!out.exists());
    let o = fxrt(&["gen", "--builtin", "random", "--div-bits", "3", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!out.exists());
    // A good set writes the whole core in both languages and a manifest per core.
    let o = fxrt(&["gen", "--builtin", "random", "--n", "16", "--m", "16", "--ise", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    // random: 2,000 triangles (11 bits) + leaf distance (n + 2 = 18 bits) + stack pointer (6)
    // + slot (64 slots × 2 units: 7) + a leaf's first and last flags.
    // Built for the default clock target, 150 MHz: its name, manifest and UCF say so.
    let name = "fxrt_intersect_n16_m16_t0_e4_tag44_c150";
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join(format!("{name}.json"))).unwrap()).unwrap();
    assert_eq!((manifest["latency_cycles"].clone(), manifest["params"]["target_mhz"].clone()), (43.into(), 150.into()));
    // The scene-dependent modules carry the scene's tag: fxrt_core_s<6 hex digits>.
    let top = |dir: &std::path::Path| -> String {
        let names: Vec<String> =
            std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
        // The core's own manifest, not a wrapper's (`…_axis.json`): a directory lists in no
        // set order.
        let is_core = |n: &&String| {
            n.strip_prefix("fxrt_core_s").and_then(|t| t.strip_suffix(".json")).is_some_and(|tag| !tag.contains('_'))
        };
        let json = names.iter().find(is_core).expect("the core's manifest");
        json.trim_end_matches(".json").to_string()
    };
    let core_name = top(&out);
    assert_eq!(core_name.len(), "fxrt_core_s".len() + 6, "{core_name}");
    let ucf = std::fs::read_to_string(out.join(format!("{core_name}.ucf"))).unwrap();
    assert!(ucf.contains("PERIOD \"clk\" 6.667 ns"), "{ucf}");
    // At 75 MHz the products take one clock: the thesis-like pipeline, 13 cycles shorter.
    let slow = dir.path().join("slow");
    let o = fxrt(&[
        "gen",
        "--builtin",
        "random",
        "--n",
        "16",
        "--m",
        "16",
        "--ise",
        "--target-mhz",
        "75",
        "--out",
        slow.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let slow_manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(slow.join("fxrt_intersect_n16_m16_t0_e4_tag44_c75.json")).unwrap())
            .unwrap();
    assert_eq!(slow_manifest["latency_cycles"], 25);
    assert!(std::fs::read_to_string(slow.join(format!("{core_name}.ucf"))).unwrap().contains("13.333 ns"));
    let core: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join(format!("{core_name}.json"))).unwrap()).unwrap();
    // What an integrator needs besides the ports: latency bounds, reset, results held,
    // the clock, the hashes naming the scene and parameters.
    assert!(core["latency_cycles"]["min"].as_u64().is_some_and(|l| l > 10), "{core}");
    assert_eq!(
        (core["interface"]["reset_cycles"].clone(), core["interface"]["result_queue_depth"].clone()),
        (1.into(), 16.into())
    );
    assert_eq!(core["interface"]["rays_held_max"], 128 + 16 + 2);
    assert_eq!(core["clock"]["target_mhz"], 150);
    assert_eq!(core["hashes"]["scene_tag"].as_str().unwrap(), &core_name["fxrt_core_".len()..]);
    assert_eq!(core["hashes"]["scene_sha256"].as_str().unwrap().len(), 64);
    // Results leave in the order rays finish, and the manifest says so.
    assert_eq!(core["params"]["results_in_order"], false, "{core}");
    assert_eq!(
        (core["params"]["ray_slots_per_unit"].clone(), core["params"]["traversal_units"].clone()),
        (64.into(), 2.into())
    );
    // The AXI4-Stream wrapper's manifest, the file an integrator of the wrapper reads, says
    // the same interface facts (its latency one clock more: its output register).
    let axis: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join(format!("{core_name}_axis.json"))).unwrap()).unwrap();
    assert_eq!(axis["latency_cycles"]["min"].as_u64(), core["latency_cycles"]["min"].as_u64().map(|l| l + 1), "{axis}");
    assert_eq!(axis["interface"]["reset_cycles"], 1);
    assert_eq!(axis["interface"]["rays_held_max"], 128 + 16 + 4);
    assert_eq!(axis["clock"], core["clock"]);
    let files = core["files"]["vhdl"].as_array().unwrap();
    assert_eq!(files.last().unwrap(), &format!("{core_name}.vhd"));
    let hex = core["files"]["verilog_memory_init"].as_array().unwrap();
    assert!(!hex.is_empty());
    let ise = core["files"]["ise"].as_array().unwrap();
    for f in files.iter().chain(core["files"]["verilog"].as_array().unwrap()).chain(hex).chain(ise) {
        assert!(out.join(f.as_str().unwrap()).exists(), "{f}");
    }
    let tcl = std::fs::read_to_string(out.join(format!("{core_name}.tcl"))).unwrap();
    assert!(tcl.contains("xc5vlx110t") && tcl.contains(&format!("xfile add \"{name}.vhd\"")), "{tcl}");
    assert!(out.join(format!("{core_name}.ucf")).exists());
    // A scene folder from `fxrt scene` gives the same core as the scene itself.
    let rom = dir.path().join("rom");
    let o = fxrt(&["scene", "--builtin", "random", "--n", "16", "--m", "16", "--out", rom.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let again = dir.path().join("again");
    let o = fxrt(&["gen", "--scene", rom.to_str().unwrap(), "--ise", "--out", again.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(top(&again), core_name, "the same scene, the same tag");
    let tag = &core_name["fxrt_core_".len()..];
    for f in [
        format!("{core_name}.vhd"),
        format!("{core_name}.v"),
        format!("fxrt_traverse_k64_{tag}.vhd"),
        format!("{core_name}.json"),
    ] {
        assert_eq!(std::fs::read(out.join(&f)).unwrap(), std::fs::read(again.join(&f)).unwrap(), "{f}");
    }
    // A scene too large for the block RAM allowed is refused, naming the option.
    let small = dir.path().join("small");
    let o = fxrt(&["gen", "--builtin", "random", "--bram-kbits", "64", "--out", small.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--bram-kbits") && !small.exists(), "{}", stderr(&o));
}

#[test]
fn test_command_reports_and_fails_on_nothing_to_run() {
    let o = fxrt(&["test", "--builtin", "cornell", "--vectors", "3000"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(text.lines().last(), Some("3000 passed, 0 failed"));
    let o = fxrt(&["test", "--vectors", "0"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn sim_command_checks_every_pixel_and_writes_render_ids() {
    let dir = tempfile::tempdir().unwrap();
    let (sim_ids, render_ids) = (dir.path().join("sim.ids"), dir.path().join("render.ids"));
    let o = fxrt(&["sim", "--builtin", "cornell", "--size", "24x20", "--ids", sim_ids.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let line: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(line["all_pixels_match"], true);
    // The box-exit unit takes one ray per 4 clocks at most.
    assert!(line["cycles_per_ray"].as_f64().unwrap() >= 4.0, "{line}");
    assert!(line["triangle_tests_per_ray"].as_f64().unwrap() > 1.0, "{line}");
    let o = fxrt(&["render", "--builtin", "cornell", "--size", "24x20", "--ids", render_ids.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&sim_ids).unwrap(), std::fs::read(&render_ids).unwrap());
    // The on-chip ray generator, from inside the box.
    let line = raygen_sim(&["--size", "16x16"]);
    assert_eq!((line["all_pixels_match"].as_bool(), line["rays"].as_u64()), (Some(true), Some(256)));
    // Refused: a generator camera outside the box, the generator in an HDL simulator.
    let o = fxrt(&["sim", "--builtin", "cornell", "--raygen", "--size", "8x8"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--eye") && stderr(&o).contains("inside the scene box"), "{}", stderr(&o));
    let o = fxrt(&["sim", "--raygen", "--sim", "ghdl", "--eye", "0,1,0", "--at", "1,1,0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--raygen") && stderr(&o).contains("Rust"), "{}", stderr(&o));
}

/// The core's manifest in folder `dir` written by `fxrt gen`.
fn manifest_in(dir: &std::path::Path) -> std::path::PathBuf {
    let is_manifest =
        |name: &str| name.starts_with("fxrt_core_") && name.ends_with(".json") && !name.ends_with("_axis.json");
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|f| is_manifest(f.file_name().unwrap().to_str().unwrap()))
        .expect("the core's manifest")
}

/// `--device` fits the shape: the ML509's top (the XC5VLX110T's 64 DSP48E take two units with
/// the products cut for them, said on stderr); with `--units` too it is refused, as is a folder
/// of ROM images (the fit runs the scene).
#[test]
fn device_fits_the_shape_and_conflicts_with_a_shape_given() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ml509");
    let o = out.to_str().unwrap();
    let board = ["gen", "--builtin", "cornell", "--size", "4x3", "--out", o, "--board", "ml509"];
    let ok = fxrt(&[&board[..], &["--device", "xc5vlx110t"]].concat());
    assert!(ok.status.success(), "{}", stderr(&ok));
    assert!(stderr(&ok).contains("chosen 2 units × 64 slots, 1 pipelines"), "{}", stderr(&ok));
    // The core's manifest states the fit: the device, the shapes counted, the one chosen.
    let plain = dir.path().join("plain");
    let g = fxrt(&["gen", "--builtin", "cornell", "--device", "xc5vlx110t", "--out", plain.to_str().unwrap()]);
    assert!(g.status.success(), "{}", stderr(&g));
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(manifest_in(&plain)).unwrap()).unwrap();
    let fit = &doc["device_fit"];
    assert_eq!((fit["device"].as_str(), fit["chosen"]["units"].as_u64()), (Some("xc5vlx110t"), Some(2)), "{fit}");
    assert_eq!(doc["params"]["traversal_units"], 2, "{doc}");
    assert_eq!(doc["params"]["multiplier_pieces"], "25x18", "{doc}");
    assert!(fit["candidates"].as_array().is_some_and(|c| c.len() > 3), "{fit}");
    // Not given, the leaf size and the stack are the fit's too, and the core is the chosen
    // build's; given, they are kept.
    assert_eq!(doc["params"]["stack_depth"], fit["chosen"]["stack_depth"], "{doc}");
    let tried = |fit: &serde_json::Value, key: &str| -> Vec<u64> {
        let mut v: Vec<u64> = fit["candidates"].as_array().unwrap().iter().map(|c| c[key].as_u64().unwrap()).collect();
        v.dedup();
        v
    };
    assert_eq!((tried(fit, "leaf_size").len(), tried(fit, "stack_depth").len() > 1), (3, true), "{fit}");
    let given = dir.path().join("given");
    let args = ["--leaf-size", "2", "--stack-depth", "24", "--out", given.to_str().unwrap()];
    let g = fxrt(&[&["gen", "--builtin", "cornell", "--device", "xc5vlx110t"][..], &args].concat());
    assert!(g.status.success(), "{}", stderr(&g));
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(manifest_in(&given)).unwrap()).unwrap();
    let fit = &doc["device_fit"];
    assert_eq!((tried(fit, "leaf_size"), tried(fit, "stack_depth")), (vec![2], vec![24]), "{fit}");
    assert_eq!(doc["params"]["stack_depth"], 24, "{doc}");
    let other = dir.path().join("other");
    let sim = ["sim", "--builtin", "cornell", "--size", "4x4", "--device", "lfe5u-85f", "--units", "2"];
    assert_rejected(&sim, "--device", &other);
    let rom = dir.path().join("rom");
    assert!(fxrt(&["scene", "--builtin", "cornell", "--out", rom.to_str().unwrap()]).status.success());
    let from_roms =
        ["gen", "--scene", rom.to_str().unwrap(), "--device", "lfe5u-85f", "--out", other.to_str().unwrap()];
    assert_rejected(&from_roms, "--device", &other);
    let o = other.to_str().unwrap();
    let external = ["gen", "--builtin", "cornell", "--memory", "external", "--device", "lfe5u-85f", "--out", o];
    assert_rejected(&external, "--device", &other);
    // A width no shape can hold is said as itself, not as a device too small.
    let wide = ["gen", "--builtin", "cornell", "--m", "64", "--c", "40", "--device", "lfe5u-85f", "--out", o];
    assert_rejected(&wide, "--c", &other);
}

/// Two pipelines, one unit each: every pixel matches, and the JSON says the shape.
#[test]
fn sim_with_two_pipelines_matches_every_pixel() {
    let o = fxrt(&["sim", "--builtin", "cornell", "--size", "8x8", "--slots", "4", "--pipelines", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((v["units"].as_u64(), v["pipelines"].as_u64()), (Some(2), Some(2)), "{v}");
    assert_eq!((v["all_pixels_match"].as_bool(), v["walk_matches"].as_bool()), (Some(true), Some(true)), "{v}");
    assert!(v["rays"].as_u64().unwrap() > 0 && v["pipeline_fill"].as_f64().unwrap() <= 1.0, "{v}");
}

/// One ray slot per traversal unit (it used to panic: the stack address has a slot bit).
#[test]
fn sim_with_one_slot_per_unit_matches_every_pixel() {
    let o = fxrt(&["sim", "--builtin", "cornell", "--size", "8x8", "--slots", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((v["slots"].as_u64(), v["units"].as_u64()), (Some(2), Some(2)), "{v}");
    assert_eq!((v["all_pixels_match"].as_bool(), v["mismatches"].as_u64()), (Some(true), Some(0)), "{v}");
    assert!(v["rays"].as_u64().unwrap() > 0, "{v}");
}

/// Shuffled rays and a stalling source: every pixel still right, the options in the JSON line,
/// the same ids as `render`; bad values refused with one line naming the option.
#[test]
fn sim_feeds_rays_shuffled_and_stalled() {
    let dir = tempfile::tempdir().unwrap();
    let (sim_ids, render_ids) = (dir.path().join("sim.ids"), dir.path().join("render.ids"));
    let size = ["--builtin", "cornell", "--size", "20x16"];
    let feed = ["--shuffle-seed", "3", "--stall-percent", "25", "--ids", sim_ids.to_str().unwrap()];
    let o = fxrt(&[&["sim"][..], &size, &feed].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let line: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((line["all_pixels_match"].as_bool(), line["mismatches"].as_u64()), (Some(true), Some(0)));
    assert_eq!((line["shuffle_seed"].as_u64(), line["stall_percent"].as_u64()), (Some(3), Some(25)));
    assert_eq!(line["stall_seed"].as_u64(), Some(1));
    assert!(line["stall_cycles"].as_u64().unwrap() > 0, "{line}");
    // The slot core returns results in the order rays finish: neither the feed's nor pixels'.
    assert_eq!(
        (line["results_in_feed_order"].as_bool(), line["results_in_pixel_order"].as_bool()),
        (Some(false), Some(false))
    );
    let o = fxrt(&[&["render"][..], &size, &["--ids", render_ids.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&sim_ids).unwrap(), std::fs::read(&render_ids).unwrap());
    let png = dir.path().join("x.png");
    let png_s = png.to_str().unwrap();
    assert_rejected(&["sim", "--stall-percent", "100", "--png", png_s], "--stall-percent", &png);
    assert_rejected(&["sim", "--stall-percent", "-5", "--png", png_s], "--stall-percent", &png);
    assert_rejected(&["sim", "--stall-seed", "2", "--png", png_s], "--stall-seed", &png);
    assert_rejected(&["sim", "--shuffle-seed", "x", "--png", png_s], "--shuffle-seed", &png);
}

/// `fxrt gen --scene DIR` wires the hardware from scene.json's layouts: a layout that is not
/// the one fxrt writes (here two fields swapped) is refused, not turned into wrong hardware.
#[test]
fn gen_refuses_a_scene_folder_with_a_foreign_layout() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene");
    let o = fxrt(&["scene", "--builtin", "thin", "--out", scene.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let path = scene.join("scene.json");
    let mut j: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let tri = j["roms"].as_array_mut().unwrap().iter_mut().find(|r| r["rom"] == "tri").unwrap();
    let fields = tri["fields"].as_array_mut().unwrap();
    let (a, b) = (fields[4]["name"].clone(), fields[5]["name"].clone());
    fields[4]["name"] = b;
    fields[5]["name"] = a;
    std::fs::write(&path, serde_json::to_vec(&j).unwrap()).unwrap();
    let out = dir.path().join("hdl");
    let o = fxrt(&["gen", "--scene", scene.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("the tri ROM layout is not the one fxrt writes"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// A one-pixel frame steps in neither direction: any field of view the camera takes works.
#[test]
fn ray_generator_takes_a_one_pixel_frame_with_a_wide_fov() {
    let line = raygen_sim(&["--size", "1x1", "--fov", "130"]);
    assert_eq!(line["all_pixels_match"], true);
}

/// `fxrt sim` with the on-chip ray generator, the Cornell box seen from inside: the JSON line.
fn raygen_sim(extra: &[&str]) -> serde_json::Value {
    let args = ["sim", "--builtin", "cornell", "--raygen", "--eye", "278,273,60", "--at", "300,250,559"];
    let o = fxrt(&[&args[..], extra].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// One triangle, one leaf-table word and a one-entry stack: one-word memories get a real
/// second word, so GHDL never reads out of range (it stops the simulation if it does).
#[test]
fn one_word_memories_simulate_in_ghdl() {
    if Command::new("ghdl").arg("--version").output().is_err() {
        eprintln!("skipped: ghdl is not installed");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("one.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let build = dir.path().join("build");
    let o = fxrt(&[
        "sim",
        obj.to_str().unwrap(),
        "--size",
        "4x4",
        "--stack-depth",
        "1",
        "--sim",
        "ghdl",
        "--build",
        build.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("\"all_pixels_match\":true"));
}

/// `fxrt gen --measured` puts a place-and-route report's clock and resources into the core's
/// manifest only when the report measured this very netlist, scene and parameters; otherwise
/// exit 2, one line naming the report, nothing written.
#[test]
fn gen_takes_measured_figures_only_for_the_same_netlist() {
    use fxrt::cores::top::{CoreParams, core_module_with};
    use fxrt::scene::images::SceneRoms;
    use fxrt::scene::{Scene, SceneSource};
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &fxrt::params::Params::default()).unwrap();
    let roms = SceneRoms::of(&scene);
    // `fxrt gen`'s defaults: 20-bit ray ids, one quotient bit per divider stage, 150 MHz.
    let p = CoreParams::new(&roms, 20, 1, 150);
    let core = core_module_with(&p, &roms, false);
    let report = |hash: &str| {
        serde_json::json!({
            "family": "ecp5", "scene": "cornell",
            "params": { "n": p.isect.n, "m": p.isect.m, "t": p.isect.t, "e": p.isect.e, "target_mhz": 150, "div_bits": 1 },
            "modules": [{ "module": core.name, "fmax_mhz": 123.45, "lut4": 11, "ff": 22, "mult18": 33, "dp16kd": 44,
                          "device": "LFE5U-85F", "package": "CABGA381", "speed_grade": 6, "seed": 3,
                          "yosys": "Yosys", "nextpnr": "nextpnr", "netlist_sha256": hash }]
        })
        .to_string()
    };
    let good = write(dir.path(), "good.json", report(&fxrt::fpga::ecp5::netlist_hash(&core)).as_bytes());
    let out = dir.path().join("out");
    let o = fxrt(&["gen", "--builtin", "cornell", "--measured", &good, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join(format!("{}.json", core.name))).unwrap()).unwrap();
    assert_eq!(manifest["clock"]["measured_fmax_mhz"], 123.45);
    assert_eq!(manifest["clock"]["measured_on"]["seed"], 3);
    // Beside the measured figures, what the netlist predicts (`fpga::ecp5::blocks`).
    let predicted = fxrt::fpga::ecp5::blocks::blocks(&core);
    let on_ecp5 = &manifest["predicted"]["LFE5U-85F"];
    assert_eq!((on_ecp5["mult18"].as_u64(), on_ecp5["dp16kd"].as_u64()), (Some(70), Some(predicted.dp16kd as u64)));
    assert_eq!(manifest["predicted"]["XC5VLX110T"]["dsp48e"], 70);
    assert_eq!(
        (manifest["resources"]["lut4"].clone(), manifest["resources"]["dp16kd"].clone()),
        (11.into(), 44.into())
    );
    // The same report for the core with its observation ports, or for another netlist.
    let reject = |extra: &[&str], file: &str, name: &str| {
        let out = dir.path().join(name);
        let mut args = vec!["gen", "--builtin", "cornell", "--out", out.to_str().unwrap(), "--measured", file];
        args.extend(extra);
        assert_rejected(&args, Path::new(file).file_name().unwrap().to_str().unwrap(), &out);
    };
    reject(&["--debug-ports"], &good, "debug");
    let stale = write(dir.path(), "stale.json", report("0123").as_bytes());
    reject(&[], &stale, "stale");
    let other = report(&fxrt::fpga::ecp5::netlist_hash(&core)).replace("\"cornell\"", "\"teapot\"");
    let other = write(dir.path(), "other.json", other.as_bytes());
    reject(&[], &other, "other");
}

/// `gen --board` refuses contradictory or impossible options in one line, writing nothing, and
/// with --no-bitstream writes the design without the ECP5 tools.
#[test]
fn gen_board_rejects_bad_options_and_writes_the_design() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("board");
    let o = out.to_str().unwrap();
    let base = ["gen", "--builtin", "cornell", "--size", "4x3", "--out", o, "--board"];
    let with = |extra: &[&'static str]| -> Vec<&str> { base.iter().copied().chain(extra.iter().copied()).collect() };
    assert_rejected(&with(&["ulx3s", "--no-bitstream", "--board-mhz", "5"]), "--board-mhz", &out);
    assert_rejected(&with(&["ml509", "--board-mhz", "nan"]), "--board-mhz", &out);
    assert_rejected(&with(&["ulx3s", "--no-bitstream", "--raygen"]), "--raygen", &out);
    assert_rejected(&with(&["ml509", "--ise"]), "--ise", &out);
    assert_rejected(&with(&["ml509", "--eye", "278,273,-800"]), "--eye", &out);
    assert_rejected(&with(&["ml509", "--led-shift", "41"]), "--led-shift", &out);
    assert_rejected(&with(&["ml509", "--ray-id-width", "3"]), "--ray-id-width", &out);
    // Four traversal units need more DSP48E than the XC5VLX110T has; 4 × 64 slots are more
    // than the closest-hit unit holds (this was a panic).
    assert_rejected(&with(&["ml509", "--units", "4", "--slots", "32"]), "--units", &out);
    assert_rejected(&with(&["ml509", "--units", "4"]), "--slots", &out);
    assert_rejected(&["gen", "--builtin", "cornell", "--units", "4", "--out", o], "--slots", &out);
    // Pipelines serve units of their own: 3 of 2 units, or 2 of 1, cannot; nor one beside
    // external memory (yet).
    assert_rejected(&["gen", "--builtin", "cornell", "--pipelines", "3", "--out", o], "--pipelines", &out);
    assert_rejected(
        &["gen", "--builtin", "cornell", "--units", "1", "--pipelines", "2", "--out", o],
        "--pipelines",
        &out,
    );
    let external = ["gen", "--builtin", "cornell", "--memory", "external", "--pipelines", "2", "--out", o];
    assert_rejected(&external, "--pipelines", &out);
    // Under --memory auto, several pipelines whose ROM copies and stacks exceed the block RAM
    // are refused for the block RAM (they used to be moved to external memory unasked, and
    // refused there for their pipelines).
    let big = ["--units", "8", "--slots", "32", "--pipelines", "2", "--leaf-size", "3", "--out", o];
    assert_rejected(&[&["gen", "--builtin", "teapot"][..], &big].concat(), "--bram-kbits", &out);
    // Without the ECP5 tools the ULX3S bitstream cannot be made: refused before anything is
    // written (--no-bitstream writes the HDL).
    let o3 = Command::new(env!("CARGO_BIN_EXE_fxrt"))
        .args(with(&["ulx3s"]))
        .env("FXRT_ECP5_BIN", dir.path().join("no-tools"))
        .output()
        .unwrap();
    assert_eq!(o3.status.code(), Some(2), "{}", stderr(&o3));
    assert!(stderr(&o3).starts_with("fxrt: --board: ") && stderr(&o3).contains("--no-bitstream"), "{}", stderr(&o3));
    assert!(!out.exists());
    // With the products cut for the DSP48E the default two traversal units need 60 of the
    // XC5VLX110T's 64 (cut 18 × 18 as for the ECP5, 70): with no shape option the ML509's core
    // is fitted to it (two units); a shape given that does not fit is refused.
    assert_rejected(&with(&["ml509", "--units", "3", "--slots", "16"]), "--units", &out);
    assert_rejected(&with(&["ml509", "--slots", "32", "--dsp", "18x18"]), "--units", &out);
    let o2 = fxrt(&with(&["ml509"]));
    assert!(o2.status.success(), "{}", stderr(&o2));
    assert!(stderr(&o2).contains("XC5VLX110T: chosen 2 units"), "{}", stderr(&o2));
    let names: Vec<String> =
        std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    for ext in [".ucf", ".tcl", ".json"] {
        assert!(names.iter().any(|n| n.starts_with("fxrt_ml509_") && n.ends_with(ext)), "{ext} in {names:?}");
    }
    // The board's manifest says the core's shape, its cut and the fit that chose it.
    let manifest = names.iter().find(|n| n.starts_with("fxrt_ml509_") && n.ends_with(".json")).unwrap();
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join(manifest)).unwrap()).unwrap();
    assert_eq!(
        (doc["core"]["traversal_units"].as_u64(), doc["core"]["multiplier_pieces"].as_str()),
        (Some(2), Some("25x18"))
    );
    assert_eq!(doc["device_fit"]["chosen"]["units"], 2, "{doc}");
}

/// `$FXRT_GOLDEN_PATH` forces the golden model's code path; a name that is no path is refused
/// (exit 2, one line naming the variable) before anything runs, and every path renders the
/// same picture.
#[test]
fn a_forced_golden_path_renders_the_same_ids() {
    let dir = tempfile::tempdir().unwrap();
    let ids = |path: &str| -> Vec<u8> {
        let out = dir.path().join(format!("{path}.bin"));
        let o = Command::new(env!("CARGO_BIN_EXE_fxrt"))
            .args(["render", "--builtin", "teapot", "--size", "48x40", "--ids", out.to_str().unwrap()])
            .env("FXRT_GOLDEN_PATH", path)
            .output()
            .unwrap();
        assert!(o.status.success(), "{path}: {}", stderr(&o));
        std::fs::read(&out).unwrap()
    };
    let auto = ids("auto");
    for path in ["reference", "scalar", "avx2", "avx512"] {
        assert_eq!(ids(path), auto, "{path}");
    }
    let bad = dir.path().join("bad.bin");
    let o = Command::new(env!("CARGO_BIN_EXE_fxrt"))
        .args(["render", "--builtin", "teapot", "--size", "8x8", "--ids", bad.to_str().unwrap()])
        .env("FXRT_GOLDEN_PATH", "sse4")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("$FXRT_GOLDEN_PATH") && stderr(&o).trim_end().lines().count() == 1, "{}", stderr(&o));
    assert!(!bad.exists());
}

/// Issue 27's small-width case: `fxrt sim --builtin teapot --n 4 --m 8 --size 8x8` exited 1 with
/// 4 mismatches (the traversal's direction sign a clock late). Now every pixel matches, and the
/// core's node steps are the golden culled walk's (`walk_matches`, which also decides the exit).
#[test]
fn sim_matches_at_small_widths_and_walks_as_the_golden_model() {
    let o = fxrt(&["sim", "--builtin", "teapot", "--n", "4", "--m", "8", "--size", "8x8"]);
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    let line: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(line["mismatches"], 0);
    assert_eq!(line["walk_matches"], true);
    assert_eq!(line["node_steps_per_ray"], line["golden_node_steps_per_ray"]);
}

#[test]
fn bench_exact_refuses_bad_options_naming_them() {
    for (args, subject) in [
        (vec!["--seconds", "0"], "--seconds"),
        (vec!["--seconds", "nan"], "--seconds"),
        (vec!["--cases", "0"], "--cases"),
        (vec!["--scenes", "/nonexistent/scenes"], "/nonexistent/scenes"),
    ] {
        let mut all = vec!["bench", "exact"];
        all.extend(&args);
        let o = fxrt(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with(&format!("fxrt: {subject}")), "{err}");
    }
}

/// `fxrt sim --memory external`: the scene read through the AXI4 port and the caches from the
/// memory model, slow and pausing, every pixel right, the walk the golden one, and the memory
/// figures in the JSON; `auto` keeps a scene that fits on chip there; tiles are one more order.
#[test]
fn sim_runs_external_memory_cores() {
    let dir = tempfile::tempdir().unwrap();
    let (ext_ids, chip_ids) = (dir.path().join("ext.ids"), dir.path().join("chip.ids"));
    let base = ["sim", "--builtin", "cornell", "--size", "16x12", "--slots", "16", "--ids"];
    let o = fxrt(
        &[
            &base[..],
            &[ext_ids.to_str().unwrap(), "--memory", "external", "--node-cache-kb", "1", "--tri-cache-kb", "1"],
            &["--mem-latency", "200", "--mem-jitter", "25", "--mem-pauses", "70", "--mem-seed", "9"],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let line: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((line["memory"].as_str(), line["all_pixels_match"].as_bool()), (Some("external"), Some(true)), "{line}");
    assert_eq!(line["walk_matches"], true, "{line}");
    for key in ["node_cache_hit_rate", "tri_cache_hit_rate", "mem_busy", "memory_stall_fraction"] {
        let v = line[key].as_f64().unwrap();
        assert!(v > 0.0 && v < 1.0, "{key} = {v}: {line}");
    }
    // Every burst is a 128-byte line of 16 beats.
    let (reads, bytes) = (line["mem_reads_per_ray"].as_f64().unwrap(), line["mem_bytes_per_ray"].as_f64().unwrap());
    assert!((bytes - 128.0 * reads).abs() < 1e-6 && bytes > 0.0, "{line}");
    let o = fxrt(&[&base[..], &[chip_ids.to_str().unwrap(), "--memory", "auto", "--ray-order", "tiles"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let line: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((line["memory"].as_str(), line["ray_order"].as_str()), (Some("onchip"), Some("tiles")), "{line}");
    assert_eq!(line["all_pixels_match"], true, "{line}");
    assert_eq!(std::fs::read(&ext_ids).unwrap(), std::fs::read(&chip_ids).unwrap());
}

/// `fxrt gen --memory external`: the core with its AXI4 read port instead of scene ROMs, the
/// image and its C header beside it (the same bytes as `fxrt scene` writes), the port's rules in
/// the manifest, byte-identical across runs; `auto` goes external for a scene too large for
/// `--bram-kbits`.
#[test]
fn gen_writes_external_memory_cores() {
    let dir = tempfile::tempdir().unwrap();
    let [a, b, sc, auto] = ["a", "b", "scene", "auto"].map(|d| dir.path().join(d));
    for out in [&a, &b] {
        let o = fxrt(&["gen", "--builtin", "cornell", "--memory", "external", "--out", out.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let o = fxrt(&["scene", "--builtin", "cornell", "--out", sc.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(a.join("scene.bin")).unwrap(), std::fs::read(sc.join("scene.bin")).unwrap());
    let names = |d: &std::path::Path| {
        let mut v: Vec<String> =
            std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    };
    assert_eq!(names(&a), names(&b));
    for f in names(&a) {
        assert_eq!(std::fs::read(a.join(&f)).unwrap(), std::fs::read(b.join(&f)).unwrap(), "{f}");
    }
    assert!(!names(&a).iter().any(|f| f.contains("brom_node")), "{:?}", names(&a));
    // The AXI4-Stream wrapper passes the read port through.
    let wrapper = names(&a).into_iter().find(|f| f.ends_with("_ext_axis.v")).expect("the AXI4-Stream wrapper");
    let text = std::fs::read_to_string(a.join(wrapper)).unwrap();
    for port in ["input wire [31:0] mem_base", "output wire [31:0] m_axi_araddr", "output wire [0:0] m_axi_arid"] {
        assert!(text.contains(port), "{port}");
    }
    let json =
        names(&a).into_iter().find(|f| f.starts_with("fxrt_core_") && f.ends_with("_ext.json")).expect("a manifest");
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(a.join(json)).unwrap()).unwrap();
    assert_eq!(doc["memory"]["axi4_read"]["arlen"], 15);
    assert!(doc["memory"]["axi4_read"]["id"].as_str().unwrap().contains("in order"));
    let verilog = names(&a).into_iter().find(|f| f.starts_with("fxrt_core_") && f.ends_with("_ext.v")).unwrap();
    let text = std::fs::read_to_string(a.join(verilog)).unwrap();
    for port in ["m_axi_araddr", "m_axi_arlen", "m_axi_rdata", "mem_base", "mem_error"] {
        assert!(text.contains(port), "{port}");
    }
    // Too large for 2,000 Kb on chip: external, whose caches fit.
    let o = fxrt(&["gen", "--builtin", "teapot", "--bram-kbits", "2000", "--out", auto.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("external memory") && auto.join("scene.bin").exists());
    let o = fxrt(&[
        "gen",
        "--builtin",
        "cornell",
        "--memory",
        "external",
        "--raygen",
        "--out",
        dir.path().join("r").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}
