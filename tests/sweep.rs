//! `fxrt sweep` as a user runs it: bad lists, a sweep of 120 configurations, shards merged
//! byte for byte, the cache, the Slurm / GNU parallel scripts, and the thesis's findings.

mod common;
use common::sweep_rows as rows;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn fxrt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fxrt")).args(args).output().expect("fxrt runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Every file under `dir` (relative path → bytes).
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                out.insert(p.strip_prefix(root).unwrap().to_path_buf(), std::fs::read(&p).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

#[test]
fn bad_lists_exit_2_with_one_line_before_anything_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let bad_obj = dir.path().join("bad.obj");
    std::fs::write(&bad_obj, "v 0 0 0\nv 1 0 0\nf 1 2 7\n").unwrap();
    for (args, expect) in [
        (vec!["--n", "29..20"], "--n: '29..20' is reversed"),
        (vec!["--m", ""], "--m: '' has an empty item"),
        (vec!["--t", "0..70:8"], "--t: 70 (in '0..70:8') is out of range"),
        (vec!["--edge-shift", "auto,x"], "--edge-shift: 'x'"),
        (vec!["--slots", "2,65"], "--slots: 65 (in '65') is out of range: must be 1..=64"),
        (vec!["--units", "1..9"], "--units: 9 (in '1..9') is out of range: must be 1..=8"),
        (vec!["--leaf-size", "0,4"], "--leaf-size: 0 (in '0') is out of range: must be 1..=64"),
        (vec!["--m", "12", "--t", "24"], "sweep: no valid parameter set"),
        (vec!["--builtin", "nosuch"], "--builtin: unknown scene 'nosuch'"),
        (vec![bad_obj.to_str().unwrap()], "bad.obj"),
        (vec!["--shard", "4/3"], "--shard"),
        (vec!["--builtin", "nosuch", "--emit-slurm"], "--builtin: unknown scene 'nosuch'"),
        (vec!["--m", "8,12", "--t", "7", "--one-at-a-time"], "the base set of --one-at-a-time is invalid"),
    ] {
        let mut a = vec!["sweep", "--size", "8x8", "--out", out.to_str().unwrap()];
        a.extend(args.iter());
        let o = fxrt(&a);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(expect), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote output");
    }
    // Merging an incomplete set of shards names the gap.
    let spec = ["sweep", "--size", "8x8", "--m", "16,32", "--builtin", "thin"];
    let shard1 = dir.path().join("s1");
    let o = fxrt(&[&spec[..], &["--shard", "1/2", "--out", shard1.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let o = fxrt(&["sweep", "merge", shard1.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("is a shard missing"), "{}", text(&o.stderr));
}

/// `--m 12,16,20..32:4 --t 0..24:8 --c C` over teapot and cornell at 48×48, then `extra`.
fn sweep(c: &str, extra: &[&str]) -> Output {
    let mut args = vec!["sweep", "--builtin", "teapot,cornell", "--size", "48x48", "--m", "12,16,20..32:4"];
    args.extend(["--t", "0..24:8", "--c", c]);
    args.extend(extra);
    let o = fxrt(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    o
}

/// 6 m × 4 T × 3 C parameter sets over two scenes: shards merge to the unsharded folder byte
/// for byte, and a rerun computes only what is new.
#[test]
fn a_two_scene_sweep_its_shards_and_its_cache() {
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let o = sweep("4,8,16", &["--out", whole.to_str().unwrap()]);
    let rows = rows(&whole);
    // T ≤ m − 2: m = 12 takes T ∈ {0, 8}, m = 16 too, m = 20 and 24 not T = 24, so 6 of the
    // 24 (m, T) pairs are skipped: 18 pairs × 3 C = 54 sets.
    assert_eq!(rows.len(), 2 * 54, "{}", text(&o.stdout));
    assert!(text(&o.stdout).starts_with(&format!("{} computed, 0 from the cache", rows.len())));
    let report = std::fs::read_to_string(whole.join("report.md")).unwrap();
    assert!(report.contains("18 parameter sets skipped") && report.contains("--t: 24 must be at most m−2"));
    for file in ["plots/error_m.png", "plots/error_t.png", "plots/pareto_dsp48e.png", "grids/teapot_c.png"] {
        assert!(report.contains(&format!("({file})")), "{file} not in the report");
        let bytes = std::fs::read(whole.join(file)).unwrap();
        let info = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().unwrap().info().clone();
        assert!(info.width > 200 && info.height > 100, "{file}");
    }
    for r in &rows {
        assert!(whole.join(&r["image"]).is_file(), "{}", r["image"]);
        assert_eq!(r["rays"], "2304");
        let parts: u64 =
            ["false_misses", "false_hits", "other_surface"].iter().map(|k| r[*k].parse::<u64>().unwrap()).sum();
        assert_eq!(parts.to_string(), r["wrong_pixels"]);
    }

    let shard_dirs: Vec<PathBuf> = (1..=3).map(|i| dir.path().join(format!("shard{i}"))).collect();
    for (i, d) in shard_dirs.iter().enumerate() {
        sweep("4,8,16", &["--shard", &format!("{}/3", i + 1), "--out", d.to_str().unwrap()]);
        assert_eq!(self::rows(d).len(), rows.len() / 3);
    }
    let merged = dir.path().join("merged");
    let mut args = vec!["sweep", "merge"];
    args.extend(shard_dirs.iter().map(|d| d.to_str().unwrap()));
    args.extend(["--out", merged.to_str().unwrap()]);
    let o = fxrt(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (a, b) = (tree(&whole), tree(&merged));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (k, v) in &a {
        assert!(b[k] == *v, "{} differs between the whole sweep and the merged shards", k.display());
    }

    // A rerun reads everything from the cache and writes the same files; a longer list
    // computes only what is new.
    let o = sweep("4,8,16", &["--out", whole.to_str().unwrap()]);
    assert!(text(&o.stdout).starts_with(&format!("0 computed, {} from the cache", rows.len())));
    assert!(tree(&whole) == a);
    let o = sweep("4,6,8,16", &["--out", whole.to_str().unwrap()]);
    let new = rows.len() / 3;
    assert!(
        text(&o.stdout).starts_with(&format!("{new} computed, {} from the cache", rows.len())),
        "{}",
        text(&o.stdout)
    );
}

#[test]
fn emitted_scripts_run_the_shards_and_the_merge() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cluster");
    let small = ["sweep", "--builtin", "thin,cornell", "--size", "16x16", "--m", "16,24,32", "--one-at-a-time"];
    let o = fxrt(
        &[&small[..], &["--emit-slurm", "--shards", "2", "--threads", "1", "--out", out.to_str().unwrap()]].concat(),
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let slurm = std::fs::read_to_string(out.join("slurm/sweep.slurm")).unwrap();
    assert!(slurm.contains("#SBATCH --array=1-2") && slurm.contains("--shard \"${SLURM_ARRAY_TASK_ID}/2\""));
    let submit = std::fs::read_to_string(out.join("slurm/submit.sh")).unwrap();
    assert!(submit.contains("--dependency=afterok:"));
    // Run what GNU parallel would run, then the merge, with the shell.
    let commands = std::fs::read_to_string(out.join("slurm/commands.txt")).unwrap();
    assert_eq!(commands.lines().count(), 2);
    for line in commands.lines() {
        let o = Command::new("sh").args(["-c", line]).output().unwrap();
        assert!(o.status.success(), "{line}: {}", text(&o.stderr));
    }
    let merge = std::fs::read_to_string(out.join("slurm/merge.slurm")).unwrap();
    let merge_line = merge.lines().last().unwrap();
    let o = Command::new("sh").args(["-c", merge_line]).output().unwrap();
    assert!(o.status.success(), "{merge_line}: {}", text(&o.stderr));
    // The same as running the sweep in one go.
    let direct = dir.path().join("direct");
    let o = fxrt(&[&small[..], &["--out", direct.to_str().unwrap()]].concat());
    assert!(o.status.success());
    let merged = out.join("results.csv");
    assert_eq!(std::fs::read(merged).unwrap(), std::fs::read(direct.join("results.csv")).unwrap());
    // The shards share OUT/cache: one more m value over three shards computes only its two
    // configurations, wherever they land.
    let more = ["sweep", "--builtin", "thin,cornell", "--size", "16x16", "--m", "16,20,24,32", "--one-at-a-time"];
    let o = fxrt(&[&more[..], &["--emit-slurm", "--shards", "3", "--out", out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let commands = std::fs::read_to_string(out.join("slurm/commands.txt")).unwrap();
    let mut computed = 0;
    for line in commands.lines() {
        let o = Command::new("sh").args(["-c", line]).output().unwrap();
        assert!(o.status.success(), "{line}: {}", text(&o.stderr));
        computed += text(&o.stdout).split(' ').next().unwrap().parse::<u32>().unwrap();
    }
    assert_eq!(computed, 2);
}

/// Seed 001 §2.1 figures 2.7–2.9 and seed 003's edge shift, with this project's numbers
/// (docs/SWEEPS.md has the full tables at 256²).
#[test]
fn the_thesis_findings_hold() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("figures");
    let o = fxrt(&[
        "sweep",
        "--builtin",
        "teapot,jackstraws",
        "--size",
        "128x128",
        "--n",
        "24,29",
        "--m",
        "8,12,16,24,32",
        "--t",
        "0,8,16,24",
        "--c",
        "0,4,8,16",
        "--one-at-a-time",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let rows = rows(&out);
    let wrong = |scene: &str, set: &[(&str, &str)]| -> u64 {
        let defaults = [("n", "29"), ("m", "32"), ("t", "0"), ("c", "16"), ("edge_shift", "auto")];
        let r = rows
            .iter()
            .find(|r| {
                r["scene"] == scene
                    && defaults
                        .iter()
                        .all(|(k, d)| r[*k] == set.iter().find(|(sk, _)| sk == k).map(|(_, v)| *v).unwrap_or(d))
            })
            .unwrap_or_else(|| panic!("{scene} {set:?} not in the sweep"));
        r["wrong_pixels"].parse().unwrap()
    };
    // Figure 2.7: a moderate m already renders the teapot correctly; small m does not.
    assert_eq!(wrong("teapot", &[]), 0);
    assert!(wrong("teapot", &[("m", "24")]) == 0);
    assert!(wrong("teapot", &[("m", "16")]) <= 10);
    assert!(wrong("teapot", &[("m", "8")]) > 500);
    // Figure 2.8: T = 24 is unacceptable, small T is harmless.
    assert!(wrong("teapot", &[("t", "8")]) <= 1);
    assert!(wrong("teapot", &[("t", "24")]) > 200);
    // Figure 2.9: too small a C culls what the ray does hit.
    assert!(wrong("teapot", &[("c", "0")]) > 200);
    assert!(wrong("teapot", &[("c", "8")]) <= 1);
    // Seed 003: E = 10 breaks jackstraws on a 24-bit grid, the adaptive E (8 there) does not.
    let out = dir.path().join("edge");
    let args = ["sweep", "--builtin", "jackstraws", "--size", "128x128", "--n", "24", "--edge-shift", "auto,10"];
    let o = fxrt(&[&args[..], &["--out", out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let e = self::rows(&out);
    let (auto, ten) = (&e[0], &e[1]);
    assert_eq!((auto["edge_shift"].as_str(), auto["e_used"].as_str(), ten["edge_shift"].as_str()), ("auto", "8", "10"));
    assert_eq!(auto["wrong_pixels"], "0");
    assert!(ten["wrong_pixels"].parse::<u64>().unwrap() > 200 && ten["tris_clamped"].parse::<u64>().unwrap() > 1000);
}

/// `--core-sim`: every configuration's frame through the whole core in the Rust simulator,
/// every ray checked against the golden model, cycles per ray reported.
#[test]
fn core_simulation_in_a_sweep_agrees_with_the_golden_model() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("core");
    let args = ["sweep", "--builtin", "cornell,thin", "--size", "24x24", "--m", "16,32", "--t", "0,12", "--core-sim"];
    let o = fxrt(&[&args[..], &["--out", out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let rows = rows(&out);
    assert_eq!(rows.len(), 8);
    for r in &rows {
        assert_eq!(r["core_mismatches"], "0", "{r:?}");
        // The box-exit unit takes one ray per 4 clocks at most.
        assert!(r["cycles_per_ray"].parse::<f64>().unwrap() >= 4.0, "{r:?}");
        assert!(r["max_stack_depth"].parse::<u32>().unwrap() >= 1 || r["scene"] == "thin", "{r:?}");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("The whole core ran 8 configurations' frames in the Rust simulator: 0 rays disagreed"));
}

/// `--slots` and `--units` as axes with `--core-sim`: a row per core shape carrying the
/// simulated core's rays per clock, triangle tests and node steps per ray and slot occupancy,
/// and throughput against area plotted and linked in the report (a few seconds).
#[test]
fn core_shapes_are_swept_and_throughput_is_plotted_against_area() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("shapes");
    let args = ["sweep", "--builtin", "thin", "--size", "8x8", "--n", "10", "--m", "12", "--slots", "2,8"];
    let args = [&args[..], &["--units", "1,2", "--core-sim", "--out", out.to_str().unwrap()]].concat();
    let o = fxrt(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let rows = rows(&out);
    let shapes: Vec<(&str, &str)> = rows.iter().map(|r| (r["slots"].as_str(), r["units"].as_str())).collect();
    assert_eq!(shapes, [("2", "1"), ("2", "2"), ("8", "1"), ("8", "2")]);
    let num = |r: &BTreeMap<String, String>, k: &str| -> f64 {
        r[k].parse().unwrap_or_else(|_| panic!("{k} = '{}' is not a number", r[k]))
    };
    for r in &rows {
        assert_eq!(r["core_mismatches"], "0", "{r:?}");
        let (rpc, cpr) = (num(r, "rays_per_clock"), num(r, "cycles_per_ray"));
        assert!((rpc * cpr - 1.0).abs() < 1e-9, "rays per clock {rpc} is not 1 / {cpr}");
        assert!(num(r, "triangle_tests_per_ray") > 0.0 && num(r, "node_steps_per_ray") > 0.0, "{r:?}");
        let occupancy = num(r, "slot_occupancy");
        assert!(occupancy > 0.0 && occupancy <= 1.0, "{r:?}");
    }
    // More slots or more units do not lower rays per clock (beyond noise).
    for a in &rows {
        for b in &rows {
            if num(a, "slots") <= num(b, "slots") && num(a, "units") <= num(b, "units") {
                assert!(num(b, "rays_per_clock") >= 0.95 * num(a, "rays_per_clock"), "{a:?} vs {b:?}");
            }
        }
    }
    // The core's shape changes the cost estimate, not the image.
    assert!(num(&rows[1], "dsp48e_est") > num(&rows[0], "dsp48e_est") && rows[0]["image"] == rows[3]["image"]);
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(
        (&json["spec"]["slots"], &json["spec"]["units"]),
        (&serde_json::json!([2, 8]), &serde_json::json!([1, 2]))
    );
    assert_eq!(json["rows"][2]["shape"], serde_json::json!({ "slots": 8, "units": 1 }));
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("## Throughput against area") && report.contains("| K (ray slots per unit) | 2, 8 |"));
    for file in ["plots/throughput_dsp48e_est.png", "plots/throughput_register_bits.png"] {
        assert!(report.contains(&format!("({file})")), "{file} not in the report");
        let bytes = std::fs::read(out.join(file)).unwrap();
        let info = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().unwrap().info().clone();
        assert!(info.width >= 800 && info.height >= 400, "{file}: {}×{}", info.width, info.height);
    }
    // Renders do not depend on the core's shape: no grid or error plot along K or U.
    assert!(!out.join("grids/thin_slots.png").exists() && !out.join("plots/error_units.png").exists());
    // A rerun takes every row from the cache and writes the same files.
    let before = tree(&out);
    let o = fxrt(&args);
    assert!(text(&o.stdout).starts_with("0 computed, 4 from the cache"), "{}", text(&o.stdout));
    assert!(tree(&out) == before);
}

/// `--device`: the shape fitted once (on the first scene at the base set) is every row's core,
/// with its pipelines; the fit is in results.json, its choice the fastest shape run among those
/// within the device, and each row's core agrees with the golden model.
#[test]
fn a_device_fits_the_cores_of_a_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fitted");
    let args = ["sweep", "--builtin", "cornell", "--size", "16x16", "--n", "20,24", "--core-sim"];
    let o = fxrt(&[&args[..], &["--device", "lfe5u-85f", "--out", out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("device LFE5U-85F: chosen"), "{}", text(&o.stderr));
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    let fit = &json["spec"]["device_fit"];
    let chosen = &fit["chosen"];
    let of = |k: &str| chosen[k].as_u64().unwrap();
    assert!(of("multipliers") <= fit["multipliers_of"].as_u64().unwrap(), "{fit}");
    assert!(of("block_ram") <= fit["block_ram_of"].as_u64().unwrap(), "{fit}");
    let best = fit["candidates"].as_array().unwrap().iter().filter_map(|c| c["rays_per_clock"].as_f64());
    assert_eq!(chosen["rays_per_clock"].as_f64(), best.reduce(f64::max));
    let rows = rows(&out);
    assert_eq!(rows.len(), 2);
    for r in &rows {
        let shape = ["slots", "units", "pipelines"].map(|k| r[k].parse::<u64>().unwrap());
        assert_eq!(shape, ["slots", "units", "pipelines"].map(of), "{r:?}");
        assert_eq!(r["core_mismatches"], "0", "{r:?}");
        let fill: f64 = r["pipeline_fill"].parse().unwrap();
        assert!(fill > 0.0 && fill <= 1.0, "per pipeline: {r:?}");
    }
    // Fitted at the narrower first n, four pipelines fit; at n = 24 they need more multipliers
    // than the device has, and that row says so (its figures still there).
    let narrow = dir.path().join("narrow");
    let args = ["sweep", "--builtin", "cornell", "--size", "16x16", "--n", "16,24", "--core-sim"];
    let o = fxrt(&[&args[..], &["--device", "lfe5u-85f", "--out", narrow.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let narrow_rows = common::sweep_rows(&narrow);
    assert_eq!((narrow_rows[0]["pipelines"].as_str(), narrow_rows[0]["error"].as_str()), ("4", ""), "{narrow_rows:?}");
    assert!(narrow_rows[1]["error"].starts_with("--device: the core needs"), "{narrow_rows:?}");
    assert!(
        narrow_rows[1]["error"].ends_with("multipliers, the LFE5U-85F has 156")
            && narrow_rows[1]["core_mismatches"] == "0"
    );
    // The fit counts cores with the scene on chip.
    let ext = dir.path().join("ext");
    let o =
        fxrt(&[&args[..], &["--device", "lfe5u-85f", "--memory", "external", "--out", ext.to_str().unwrap()]].concat());
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).starts_with("fxrt: --device:") && text(&o.stderr).lines().count() == 1,
        "{}",
        text(&o.stderr)
    );
    assert!(!ext.exists());
}

/// `--memory external --core-sim`: the memory's latency and the node cache's size as axes, a
/// row per point with the memory side's figures, every ray against the golden model, and rays
/// per clock and bytes per ray plotted against each and linked in the report.
#[test]
fn external_memory_sweeps_plot_throughput_and_bytes_per_ray_against_latency_and_cache_size() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("memory");
    let args = ["sweep", "--builtin", "teapot", "--size", "8x8", "--memory", "external", "--mem-latency", "1,100"];
    let args = [&args[..], &["--node-cache-kb", "2,16", "--tri-cache-kb", "4", "--core-sim", "--out"]].concat();
    let o = fxrt(&[&args[..], &[out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let rows = rows(&out);
    let points: Vec<(&str, &str, &str)> = rows
        .iter()
        .map(|r| (r["mem_latency"].as_str(), r["node_cache_kb"].as_str(), r["tri_cache_kb"].as_str()))
        .collect();
    assert_eq!(points, [("1", "2", "4"), ("1", "16", "4"), ("100", "2", "4"), ("100", "16", "4")]);
    let num = |r: &BTreeMap<String, String>, k: &str| -> f64 {
        r[k].parse().unwrap_or_else(|_| panic!("{k} = '{}' is not a number", r[k]))
    };
    for r in &rows {
        assert_eq!(r["core_mismatches"], "0", "{r:?}");
        assert!(num(r, "mem_bytes_per_ray") > 0.0 && num(r, "mem_reads_per_ray") > 0.0, "{r:?}");
        for k in ["node_cache_hit_rate", "tri_cache_hit_rate", "mem_busy", "memory_stall_fraction"] {
            assert!((0.0..=1.0).contains(&num(r, k)), "{k}: {r:?}");
        }
    }
    // A larger node cache hits more and takes more block RAM; a longer latency costs clocks.
    for (small, large) in [(0, 1), (2, 3)] {
        assert!(num(&rows[large], "node_cache_hit_rate") > num(&rows[small], "node_cache_hit_rate"));
        assert!(num(&rows[large], "cache_bram_bits") > num(&rows[small], "cache_bram_bits"));
    }
    for (near, far) in [(0, 2), (1, 3)] {
        assert!(num(&rows[far], "rays_per_clock") < num(&rows[near], "rays_per_clock"), "{rows:?}");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("## External memory") && report.contains("| L (memory latency, clocks) | 1, 100 |"));
    for what in ["rays_per_clock", "bytes_per_ray"] {
        for axis in ["mem-latency", "node-cache-kb"] {
            let file = format!("plots/memory_{what}_{axis}.png");
            assert!(report.contains(&format!("({file})")), "{file} not in the report");
            let bytes = std::fs::read(out.join(&file)).unwrap();
            let info = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().unwrap().info().clone();
            assert!(info.width >= 800 && info.height >= 400, "{file}: {}×{}", info.width, info.height);
        }
    }
    // The memory's lists belong to external sweeps, and are checked before anything runs.
    for (extra, expect) in [
        (vec!["--mem-latency", "40"], "--mem-latency: is an axis of external-memory sweeps: add --memory external"),
        (
            vec!["--memory", "external", "--mem-latency", "0,40"],
            "--mem-latency: 0 (in '0') is out of range: must be 1..=1000",
        ),
        (
            vec!["--memory", "external", "--node-cache-kb", "3"],
            "--node-cache-kb: 3 KB: a cache must hold a power of two",
        ),
        (vec!["--memory", "auto"], "--memory: a sweep names onchip or external"),
    ] {
        let bad = dir.path().join("bad");
        let o = fxrt(&[&["sweep", "--size", "8x8", "--out", bad.to_str().unwrap()][..], &extra[..]].concat());
        let err = text(&o.stderr);
        assert_eq!((o.status.code(), err.lines().count()), (Some(2), 1), "{extra:?}: {err}");
        assert!(err.contains(expect), "{extra:?}: {err}");
        assert!(!bad.exists());
    }
}
