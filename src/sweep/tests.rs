use super::eval::quality;
use super::scene_labels;
use super::slurm::shell_quote;
use super::*;
use crate::render::Frame;

fn spec() -> SweepSpec {
    SweepSpec {
        scenes: vec![SceneSpec::Builtin("teapot".into()), SceneSpec::Builtin("cornell".into())],
        camera: CameraSpec { eye: None, at: None, up: [0.0, 1.0, 0.0], fov: 45.0, width: 16, height: 16 },
        n: vec![29],
        m: vec![12, 32],
        t: vec![0, 24],
        c: vec![16],
        edge_shift: vec![EdgeShift::Auto, EdgeShift::Fixed(10)],
        leaf_size: vec![4],
        stack_depth: 32,
        tree: TreeSplit::Sah,
        one_at_a_time: false,
        synth: false,
        core_sim: false,
        target_mhz: 150,
        slots: vec![crate::cores::top::DEFAULT_SLOTS],
        units: vec![crate::cores::top::DEFAULT_UNITS],
        pipelines: 1,
        device_fit: None,
        ecp5: None,
        memory: None,
    }
}

#[test]
fn cross_product_skips_sets_that_are_invalid_together() {
    let plan = spec().plan().unwrap();
    // m = 12 allows T ≤ 10: the two (m = 12, T = 24) sets are skipped, and say why.
    assert_eq!(plan.sets.len(), 6);
    assert_eq!(plan.skipped.len(), 2);
    assert!(plan.skipped.iter().all(|s| s.params.m == 12 && s.params.t == 24 && s.reason.starts_with("--t: 24")));
    assert_eq!(plan.configs.len(), 12);
    // Scenes vary fastest; indices are positions.
    assert!(plan.configs.iter().enumerate().all(|(i, c)| c.index == i && c.scene == i % 2));
    assert_eq!(plan.configs[2].params, Params { m: 12, edge_shift: EdgeShift::Fixed(10), ..Params::default() });
}

#[test]
fn no_valid_set_is_an_error_before_anything_runs() {
    let s = SweepSpec { m: vec![12], t: vec![24], ..spec() };
    assert!(s.plan().unwrap_err().to_string().contains("no valid parameter set"));
    let s = SweepSpec { scenes: vec![], ..spec() };
    assert!(s.plan().is_err());
}

#[test]
fn one_at_a_time_varies_each_parameter_around_the_base() {
    let s = SweepSpec { one_at_a_time: true, n: vec![20, 24], m: vec![16, 32], t: vec![0, 8], ..spec() };
    let plan = s.plan().unwrap();
    // n is not at its default 29 in the list: the base takes the list's first value.
    assert_eq!(plan.base, Set { params: Params { n: 20, ..Params::default() }, shape: CoreShape::default() });
    let base = plan.base.params;
    let expected = vec![
        base,
        Params { n: 24, ..base },
        Params { m: 16, ..base },
        Params { edge_shift: EdgeShift::Fixed(10), ..base },
        Params { t: 8, ..base },
    ];
    assert_eq!(plan.sets.iter().map(|s| s.params).collect::<Vec<_>>(), expected);
}

#[test]
fn shards_partition_the_configurations() {
    let plan = spec().plan().unwrap();
    let shards: Vec<Shard> = (1..=3).map(|i| Shard::parse(&format!("{i}/3")).unwrap()).collect();
    for c in &plan.configs {
        assert_eq!(shards.iter().filter(|s| s.takes(c.index)).count(), 1);
    }
    assert!(Shard::parse("0/3").is_err() && Shard::parse("4/3").is_err() && Shard::parse("1/0").is_err());
    assert!(Shard::parse("2").is_err());
}

#[test]
fn labels_are_unique_and_file_safe() {
    let scenes = vec![
        SceneSpec::Obj("a/teapot.obj".into()),
        SceneSpec::Obj("b/teapot.obj".into()),
        SceneSpec::Obj("my scene.obj".into()),
        SceneSpec::Builtin("cornell".into()),
    ];
    assert_eq!(scene_labels(&scenes), vec!["teapot-1", "teapot-2", "my_scene", "cornell"]);
    let scenes = vec![
        SceneSpec::Obj("a/teapot.obj".into()),
        SceneSpec::Obj("b/teapot.obj".into()),
        SceneSpec::Obj("teapot-1.obj".into()),
    ];
    assert_eq!(scene_labels(&scenes), vec!["teapot-2", "teapot-3", "teapot-1"]);
    assert_eq!(params_label(&Params::default()), "n29_m32_eauto_t0_c16");
    assert_eq!(params_label(&Params { leaf_size: 2, ..Params::default() }), "n29_m32_eauto_t0_c16_l2");
    assert_eq!(params_label(&Params { tree: TreeSplit::Middle, ..Params::default() }), "n29_m32_eauto_t0_c16_middle");
}

#[test]
fn words_are_quoted_for_the_shell_only_when_needed() {
    assert_eq!(shell_quote("/data/my scene.obj"), "'/data/my scene.obj'");
    assert_eq!(shell_quote("it's"), r"'it'\''s'");
    assert_eq!(shell_quote("--n"), "--n");
}

fn frame(ids: &[i32], depth: &[f64]) -> Frame {
    Frame {
        width: ids.len() as u32,
        height: 1,
        ids: ids.to_vec(),
        depth: depth.to_vec(),
        shade: vec![0.5; ids.len()],
        rays: ids.len() as u64,
        hits: 0,
        seconds: 0.0,
    }
}

#[test]
fn quality_sorts_pixels_into_kinds_of_error() {
    let inf = f64::INFINITY;
    let reference = frame(&[1, 2, -1, 3, 4, 5], &[10.0, 10.0, inf, 10.0, 10.0, 10.0]);
    // pixel 1: false miss; 2: false hit; 3: neighbour (same distance); 4: other surface;
    // 5: same triangle, t off by 1e-4.
    let golden = frame(&[1, -1, 7, 8, 9, 5], &[10.0, inf, 3.0, 10.000001, 12.0, 10.001]);
    let q = quality(&golden, &reference, &[1, 2, -1, 3, 4, 5]);
    assert_eq!((q.false_misses, q.false_hits, q.other_triangle, q.other_surface), (1, 1, 2, 1));
    assert_eq!(q.wrong_pixels, 3);
    assert_eq!(q.diff_vs_default, 4);
    assert_eq!((q.ref_hits, q.hits, q.rays), (5, 5, 6));
    assert!((q.t_rel_max - 1e-4).abs() < 1e-12);
    assert!((q.t_rel_mean - 0.5e-4).abs() < 1e-12);
}

#[test]
fn the_base_set_must_be_valid_and_plans_have_a_size_limit() {
    // m = 8 allows T ≤ 6: one at a time around (m = 8, T = 7) is refused...
    let s = SweepSpec { m: vec![8, 12], t: vec![7], one_at_a_time: true, ..spec() };
    assert!(matches!(s.plan(), Err(e) if e.to_string().contains("the base set of --one-at-a-time is invalid")));
    // ...a cross product takes its first valid set as the base for grids and plots.
    let s = SweepSpec { one_at_a_time: false, ..s };
    let plan = s.plan().unwrap();
    assert_eq!((plan.base.params.m, plan.base.params.t), (12, 7));
    let s = SweepSpec {
        n: (4..=40).collect(),
        m: (8..=64).collect(),
        t: (0..=62).collect(),
        c: (0..=64).collect(),
        ..spec()
    };
    assert!(matches!(s.plan(), Err(e) if e.to_string().contains("is more than 1000000")));
    let s = SweepSpec { c: vec![], ..spec() };
    assert_eq!(s.plan().unwrap_err().to_string(), "--c: the list is empty");
}

#[test]
fn slurm_shards_are_checked_and_the_scripts_written() {
    use super::slurm::{check_shards, emit};
    assert!(check_shards(1, 1).is_ok() && check_shards(1000, 5000).is_ok());
    assert_eq!(check_shards(0, 10).unwrap_err().subject, "--shards");
    assert!(check_shards(11, 10).is_err(), "more shards than configurations");
    assert!(check_shards(1001, 5000).is_err(), "Slurm's array limit");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sw");
    assert!(emit(&spec(), 4, &out, &out.join("cache"), 5, 2).is_err());
    assert!(!out.exists(), "nothing written for a refused shard count");
    emit(&spec(), 4, &out, &out.join("cache"), 2, 3).unwrap();
    let commands = std::fs::read_to_string(out.join("slurm/commands.txt")).unwrap();
    assert_eq!(commands.lines().count(), 2);
    assert!(commands.contains("--threads 3 --shard 2/2"), "{commands}");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = |f: &str| std::fs::metadata(out.join("slurm").join(f)).unwrap().permissions().mode();
        assert!(mode("submit.sh") & 0o111 != 0 && mode("sweep.slurm") & 0o111 == 0);
    }
}

/// Rows of one sweep are reused only by a sweep that would compute the same: the family, the
/// ECP5 modules and seed, and the clock target are in the key; a sweep without them keeps the
/// key it always had, and its results.json does not mention them.
/// The `thin` scene loaded for `spec()`'s camera at the defaults (for its keys).
fn thin_ctx() -> eval::SceneCtx {
    let thin = SceneSpec::Builtin("thin".into());
    eval::SceneCtx::load(&thin, "thin".into(), &spec().camera, &Params::default(), &[4]).unwrap()
}

#[test]
fn cache_keys_tell_families_seeds_targets_and_core_shapes_apart() {
    let ctx = thin_ctx();
    let p = Params::default();
    let d = CoreShape::default();
    let xc5v = SweepSpec { synth: true, ..spec() };
    let ecp5 = SweepSpec { ecp5: Some(Ecp5Choice { modules: vec!["core".into()], seed: 1 }), ..xc5v.clone() };
    let keys = [
        ctx.key(&p, d, &spec()),
        ctx.key(&p, d, &xc5v),
        ctx.key(&p, d, &ecp5),
        ctx.key(&p, d, &SweepSpec { ecp5: Some(Ecp5Choice { modules: vec!["core".into()], seed: 2 }), ..ecp5.clone() }),
        ctx.key(
            &p,
            d,
            &SweepSpec { ecp5: Some(Ecp5Choice { modules: vec!["divider".into()], seed: 1 }), ..ecp5.clone() },
        ),
        ctx.key(&p, d, &SweepSpec { target_mhz: 100, ..ecp5.clone() }),
        ctx.key(&p, d, &SweepSpec { target_mhz: 100, ..xc5v.clone() }),
        ctx.key(&p, d, &SweepSpec { target_mhz: 100, ..spec() }),
        ctx.key(&p, CoreShape { slots: 4, ..d }, &spec()),
        ctx.key(&p, CoreShape { units: 1, ..d }, &spec()),
    ];
    let distinct: std::collections::BTreeSet<&String> = keys.iter().collect();
    assert_eq!(distinct.len(), keys.len(), "{keys:?}");
    // The key of a sweep without the new options is the one it had before them: row format 1
    // (rows without --core-sim are what they were), no shape, whatever the lists hold.
    let c = &ctx.camera;
    let before = |params: &Params, core_sim: bool| {
        let text = serde_json::json!({
            "fxrt": env!("CARGO_PKG_VERSION"), "row_format": 1, "scene": "builtin:thin",
            "camera": [c.eye, c.at, c.up, [c.fov_deg, c.width as f64, c.height as f64]],
            "params": params, "synth": true, "core_sim": core_sim,
        });
        use sha2::Digest;
        format!("{:x}", sha2::Sha256::digest(text.to_string().as_bytes()))[..20].to_string()
    };
    assert_eq!(keys[1], before(&p, false));
    let swept = SweepSpec { slots: vec![8, 64], units: vec![1, 2], leaf_size: vec![2, 4], ..xc5v.clone() };
    assert_eq!(ctx.key(&p, d, &swept), keys[1], "the default shape in a sweep of shapes");
    let leaf2 = Params { leaf_size: 2, ..p };
    assert_eq!(ctx.key(&leaf2, d, &swept), before(&leaf2, false), "a leaf size as --leaf-size 2 had it");
    // Rows of --core-sim gained figures (row format 2): their old cache entries do not match.
    let core = SweepSpec { core_sim: true, ..xc5v.clone() };
    assert_ne!(ctx.key(&p, d, &core), before(&p, true));
    let json = serde_json::to_string(&xc5v).unwrap();
    assert!(!["target_mhz", "ecp5", "slots", "units"].iter().any(|k| json.contains(k)), "{json}");
    assert_eq!(serde_json::from_str::<SweepSpec>(&json).unwrap(), xc5v);
    let ecp5 = SweepSpec { target_mhz: 100, slots: vec![2], units: vec![1], ..ecp5 };
    assert_eq!(serde_json::from_str::<SweepSpec>(&serde_json::to_string(&ecp5).unwrap()).unwrap(), ecp5);
}

/// A row with placed modules: its cells sit under the columns named after the module, before
/// image, error and key, in the spec's module order; a module that did not place leaves its
/// cells empty. Without ecp5 the columns are the ones they were.
#[test]
fn ecp5_columns_follow_the_modules() {
    use super::eval::Row;
    use super::pnr::{FIELDS, PlacedModule};
    use crate::fpga::ecp5::{CriticalPath, Timing};
    let timing = |module: &str, fmax: f64, latency: Option<u32>| Timing {
        module: module.into(),
        device: "LFE5U-85F".into(),
        package: "CABGA381".into(),
        speed_grade: 6,
        target_mhz: 150.0,
        fmax_mhz: fmax,
        critical_path: CriticalPath { start: "u_dut.a".into(), end: "u_dut.b".into(), nets: vec![], delay_ns: 7.5 },
        lut4: 100,
        ff: 90,
        mult18: 2,
        dp16kd: 1,
        wrapper_ff: 9,
        latency_cycles: latency,
        yosys: "Yosys".into(),
        nextpnr: "nextpnr".into(),
        placer: "heap".into(),
        seed: 1,
        netlist_sha256: String::new(),
        slow_paths: Vec::new(),
        groups_over: None,
        endpoints_over: None,
    };
    let modules = vec!["divider".to_string(), "intersect".into(), "core".into()];
    let s = SweepSpec { synth: true, core_sim: true, ecp5: Some(Ecp5Choice { modules, seed: 1 }), ..spec() };
    let row = Row {
        index: 0,
        key: "k".into(),
        scene: "thin".into(),
        params: Params::default(),
        shape: CoreShape::default(),
        e_used: None,
        quality: None,
        cost: None,
        synth: None,
        core: Some(eval::CoreRun {
            cycles_per_ray: 130.0,
            rays_per_clock: 1.0 / 130.0,
            fill: 0.3,
            triangle_tests_per_ray: 39.0,
            node_steps_per_ray: 60.0,
            slot_occupancy: 0.9,
            max_stack_depth: 4,
            mismatches: 0,
        }),
        memory: None,
        ecp5: vec![
            PlacedModule { kind: "divider".into(), timing: timing("fxrt_div", 172.1, Some(31)) },
            PlacedModule { kind: "core".into(), timing: timing("fxrt_core", 113.3, None) },
        ],
        mrays_per_s_at_fmax: None,
        error: None,
    };
    assert_eq!(super::pnr::clock(&row.ecp5), Some(113.3), "the whole core's Fmax, not the slowest module's");
    let bytes = output::csv_bytes(&s, std::slice::from_ref(&row));
    let mut r = csv::Reader::from_reader(bytes.as_slice());
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let cells: Vec<String> = r.records().next().unwrap().unwrap().iter().map(String::from).collect();
    let at = |name: &str| cells[header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no {name}"))].clone();
    assert_eq!(header.len(), output::CSV_COLUMNS.len() + output::CORE_COLUMNS.len() + 3 * FIELDS.len() + 1);
    assert_eq!(header[header.len() - 4..], ["mrays_per_s_at_fmax", "image", "error", "key"]);
    assert_eq!(header[header.len() - 5], "core_path_ns");
    assert_eq!(
        (at("divider_fmax_mhz"), at("divider_latency"), at("core_fmax_mhz")),
        ("172.1".into(), "31".into(), "113.3".into())
    );
    assert_eq!(
        (at("core_latency"), at("intersect_fmax_mhz"), at("core_path_end")),
        ("".into(), "".into(), "u_dut.b".into())
    );
    assert_eq!(
        (at("core_lut4"), at("core_ff"), at("core_wrapper_ff"), at("core_mult18"), at("core_dp16kd")),
        ("100".into(), "90".into(), "9".into(), "2".into(), "1".into())
    );
    assert_eq!(at("key"), "k");
    // A row read back from the cache is the row.
    let back: Row = serde_json::from_slice(&serde_json::to_vec(&row).unwrap()).unwrap();
    assert_eq!(back, row);
    let plain = output::csv_bytes(&SweepSpec { ecp5: None, core_sim: false, ..s }, &[row]);
    let first = String::from_utf8(plain).unwrap().lines().next().unwrap().to_string();
    assert_eq!(first, output::CSV_COLUMNS.join(","));
}

/// Leaf size, ray slots and units are axes like n, m, E, T and C: in the cross product (the
/// units fastest, scenes faster still) and one at a time around the base; a parameter set that
/// is invalid is skipped once, whatever shapes come with it.
#[test]
fn leaf_size_slots_and_units_are_axes() {
    let s = SweepSpec { leaf_size: vec![2, 4], slots: vec![8, 64], units: vec![1, 2, 4], ..spec() };
    let plan = s.plan().unwrap();
    // 6 valid (n, m, E, T, C) sets, as in the test above, × 2 leaf sizes × 2 × 3 shapes.
    assert_eq!(plan.sets.len(), 6 * 2 * 2 * 3);
    assert_eq!(plan.configs.len(), 2 * plan.sets.len());
    assert_eq!(plan.skipped.len(), 2 * 2, "(m = 12, T = 24) at each leaf size, once for all shapes");
    assert_eq!(s.swept_axes(), vec![Axis::M, Axis::EdgeShift, Axis::T, Axis::LeafSize, Axis::Slots, Axis::Units]);
    let shapes: Vec<(u32, u32)> = plan.sets[..6].iter().map(|x| (x.shape.slots, x.shape.units)).collect();
    assert_eq!(shapes, [(8, 1), (8, 2), (8, 4), (64, 1), (64, 2), (64, 4)]);
    assert!(plan.sets[..6].iter().all(|x| x.params == Params { m: 12, leaf_size: 2, ..Params::default() }));
    assert_eq!(plan.sets[6].params.leaf_size, 4);
    let c = &plan.configs[3];
    assert_eq!((c.index, c.scene, c.shape), (3, 1, CoreShape { slots: 8, units: 2, ..CoreShape::default() }));
    // The base: each at its default where listed (leaf 4, K 64, U 2).
    assert_eq!(plan.base.shape, CoreShape::default());
    assert_eq!(plan.base.params.leaf_size, 4);
    assert_eq!(s.set_text(&plan.base), "n=29 m=32 E=auto T=0 C=16 leaf=4 K=64 U=2");
    assert_eq!(spec().set_text(&plan.base), "n=29 m=32 E=auto T=0 C=16", "only swept new axes are named");
    // One at a time: the base, then each axis's other values in list order.
    let one = SweepSpec { one_at_a_time: true, m: vec![32], t: vec![0], edge_shift: vec![EdgeShift::Auto], ..s };
    let plan = one.plan().unwrap();
    let base = plan.base;
    let expected = vec![
        base,
        Set { params: Params { leaf_size: 2, ..base.params }, ..base },
        Set { shape: CoreShape { slots: 8, units: 2, ..CoreShape::default() }, ..base },
        Set { shape: CoreShape { slots: 64, units: 1, ..CoreShape::default() }, ..base },
        Set { shape: CoreShape { slots: 64, units: 4, ..CoreShape::default() }, ..base },
    ];
    assert_eq!(plan.sets, expected);
    assert_eq!(set_label(&expected[2]), "n29_m32_eauto_t0_c16_k8_u2");
    // Lists without the default: the base takes the first value.
    let s = SweepSpec { slots: vec![16, 8], units: vec![4], leaf_size: vec![8, 1], ..spec() };
    let base = s.plan().unwrap().base;
    assert_eq!((base.shape, base.params.leaf_size), (CoreShape { slots: 16, units: 4, ..CoreShape::default() }, 8));
    let s = SweepSpec { slots: vec![], ..spec() };
    assert_eq!(s.plan().unwrap_err().to_string(), "--slots: the list is empty");
}

/// A results.json spec written before the leaf size, slots and units became lists (leaf_size a
/// number, slots and units absent, or numbers as the last single-valued build wrote them) reads
/// back as the same sweep; a spec that does not sweep them writes what those builds wrote.
#[test]
fn specs_written_before_the_lists_read_back_the_same() {
    let old = r#"{"scenes":[{"builtin":"thin"}],"camera":{"eye":null,"at":null,"up":[0.0,1.0,0.0],"fov":45.0,
        "width":16,"height":16},"n":[29],"m":[12,32],"t":[0,24],"c":[16],"edge_shift":["auto",{"fixed":10}],
        "leaf_size":2,"stack_depth":32,"one_at_a_time":false,"synth":false,"core_sim":true}"#;
    let s: SweepSpec = serde_json::from_str(old).unwrap();
    assert_eq!((s.leaf_size.clone(), s.slots.clone(), s.units.clone()), (vec![2], vec![64], vec![2]));
    assert!(s.default_core_shape());
    let written = serde_json::to_value(&s).unwrap();
    assert_eq!(written["leaf_size"], serde_json::json!(2));
    assert!(written.get("slots").is_none() && written.get("units").is_none());
    assert_eq!(written, serde_json::from_str::<serde_json::Value>(old).unwrap());
    let single = old.replace(r#""core_sim":true"#, r#""core_sim":true,"slots":4,"units":1"#);
    let s: SweepSpec = serde_json::from_str(&single).unwrap();
    assert_eq!((s.slots.clone(), s.units.clone()), (vec![4], vec![1]));
    assert_eq!(serde_json::to_value(&s).unwrap(), serde_json::from_str::<serde_json::Value>(&single).unwrap());
    // Lists are written as lists and read back.
    let lists = SweepSpec { leaf_size: vec![2, 8], slots: vec![8, 64], units: vec![1, 2], ..s };
    let text = serde_json::to_string(&lists).unwrap();
    assert!(text.contains(r#""leaf_size":[2,8]"#) && text.contains(r#""slots":[8,64],"units":[1,2]"#), "{text}");
    assert_eq!(serde_json::from_str::<SweepSpec>(&text).unwrap(), lists);
    assert!(serde_json::from_str::<SweepSpec>(&old.replace(r#""leaf_size":2"#, r#""leaf_size":"2""#)).is_err());
}

/// `--memory external`: the latency and the two caches' sizes are axes of the core's shape
/// (varied last), named where swept, in the key and the label; on-chip sweeps keep their keys.
#[test]
fn memory_latency_and_cache_sizes_are_axes_of_external_sweeps() {
    use super::memory::{MemoryPoint, MemorySweep};
    let memory = MemorySweep {
        mem_bits: 64,
        cache_line: 128,
        ways: 2,
        tiles: false,
        latency: vec![1, 40, 200],
        node_cache_kb: vec![32],
        tri_cache_kb: vec![16, 64],
    };
    let s = SweepSpec { m: vec![32], t: vec![0], edge_shift: vec![EdgeShift::Auto], memory: Some(memory), ..spec() };
    let plan = s.plan().unwrap();
    assert_eq!(plan.sets.len(), 3 * 2);
    assert_eq!(s.swept_axes(), vec![Axis::MemLatency, Axis::TriCacheKb]);
    let points: Vec<(u32, u32)> =
        plan.sets.iter().map(|x| (x.shape.memory.latency, x.shape.memory.tri_cache_kb)).collect();
    assert_eq!(points, [(1, 16), (1, 64), (40, 16), (40, 64), (200, 16), (200, 64)]);
    // The base: the defaults, 40 clocks and 32 + 64 KB.
    assert_eq!(plan.base.shape.memory, MemoryPoint::default());
    assert_eq!(s.set_text(&plan.base), "n=29 m=32 E=auto T=0 C=16 L=40 tri KB=64");
    assert!(Axis::MEMORY.iter().all(|a| !a.changes_image()));
    assert_eq!(set_label(&plan.sets[0]), "n29_m32_eauto_t0_c16_lat1_nc32_tc16");
    assert_eq!(set_label(&plan.base), "n29_m32_eauto_t0_c16");
    // Every point has its own key; the same point on chip keeps the key it always had.
    let ctx = thin_ctx();
    let p = Params::default();
    let keys: std::collections::BTreeSet<String> = plan.sets.iter().map(|x| ctx.key(&p, x.shape, &s)).collect();
    assert_eq!(keys.len(), plan.sets.len());
    assert!(!keys.contains(&ctx.key(&p, CoreShape::default(), &spec())));
    // Written and read back; an on-chip spec writes no memory at all.
    let text = serde_json::to_string(&s).unwrap();
    assert_eq!(serde_json::from_str::<SweepSpec>(&text).unwrap(), s);
    assert!(!serde_json::to_string(&spec()).unwrap().contains("memory"));
}
