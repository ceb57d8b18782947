//! The differential campaign (`fxrt bench exact`, `verify::exact`): a short run finds nothing on
//! random scenes, parameters, shapes, cameras and feeds (and the shared OBJ scenes when
//! `../shared/scenes` is there); issue 27's interior disagreement stays fixed; a finding's
//! reproducer is self-contained — its `fxrt sim` command runs the same frame again.

mod common;

use fxrt::cores::top::CoreParams;
use fxrt::model::camera::Camera;
use fxrt::params::Params;
use fxrt::scene::Scene;
use fxrt::scene::images::SceneRoms;
use fxrt::verify::exact::{self, Campaign, Verdict, draw, repro};
use fxrt::verify::feed::Stalls;
use fxrt::verify::frame::{frame_rays, golden_walk, mismatches, simulate_rust};
use std::process::Command;

/// 24 cases of seed 27 (the same 24 on every machine: the case budget ends the run, the time
/// budget is only a guard), with the shared scenes among those drawn when they are there.
#[test]
fn a_short_campaign_finds_no_disagreement() {
    let files = common::shared_scenes().unwrap_or_else(|| {
        common::say("skipped: ../shared/scenes is not there; the campaign drew random and built-in scenes only");
        Vec::new()
    });
    let out = tempfile::tempdir().unwrap();
    let c = Campaign {
        seed: 27,
        budget: std::time::Duration::from_secs(3600),
        max_cases: Some(24),
        files,
        out: out.path().to_path_buf(),
        hdl: None,
    };
    let r = exact::campaign(&c, &|_, _| {}).unwrap();
    assert_eq!(r.cases, 24);
    assert_eq!((r.findings, r.panics, r.disagreeing_rays), (0, 0, 0), "{r:?}");
    assert!(r.first.is_none() && std::fs::read_dir(out.path()).unwrap().next().is_none());
    // The run compared something: most cases ran, with cameras inside the scene box too.
    assert!(r.cases - r.refused >= 18 && r.rays > 1000 && r.inside_cameras >= 4, "{r:?}");
    assert!(r.scenes >= 12 && r.shapes >= 18 && r.parameter_sets >= 18, "{r:?}");
    // Some cases ran with the scene in external memory (a third are drawn so; some refused).
    assert!(r.external_cases >= 3, "{r:?}");
}

/// Issue 27's interior disagreement at the default parameters, on a random room with boxes
/// (walls and furniture share planes, so clip planes often lie exactly at a node's entry
/// distance), seen from inside: before the traversal's sign fix the core gave 7 wrong hits on
/// this frame and walked differently from the culled golden walk.
#[test]
fn an_interior_at_default_parameters_matches_and_walks_as_specified() {
    let scene = Scene::build("rooms", exact::soups::scene("rooms", 8), &Params::default()).unwrap();
    let (lo, hi) = fxrt::model::camera::world_bounds(&scene);
    let at: [f64; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let eye = [lo[0] + 0.3 * (hi[0] - lo[0]), at[1], lo[2] + 0.2 * (hi[2] - lo[2])];
    let cam = Camera { eye, at, up: [0.0, 1.0, 0.0], fov_deg: 70.0, width: 24, height: 24 };
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::shaped(
        &roms,
        &fxrt::cores::top::CoreSpec {
            id_width: 10,
            div_bits: 1,
            target_mhz: 150,
            slots: 64,
            units: 2,
            pipelines: 1,
            ..Default::default()
        },
    );
    let rays = frame_rays(&scene, &cam);
    let (results, stats) = simulate_rust(&p, &roms, &rays, &Stalls::none(), &|_| {});
    assert_eq!(mismatches(&scene, &rays, &results), 0);
    assert_eq!((stats.visits + stats.culls, stats.busy_cycles), golden_walk(&scene, &rays));
}

/// A finding written out: `scene.obj` reads back to the same triangles, and `command.txt` run
/// as it stands (the binary in place of `fxrt`) gives the same frame — the same rays, cycles
/// and node steps as the campaign's run of the case.
#[test]
fn a_reproducer_is_self_contained() {
    let out = tempfile::tempdir().unwrap();
    // The first case of seed 5 that runs (a random scene, drawn fresh).
    let run = (0..20).map(|i| exact::run_case(5, i, &[], None)).find(|r| matches!(r.verdict, Verdict::Ran(_))).unwrap();
    assert!(
        matches!(run.case.scene, draw::CaseScene::Random { .. })
            || matches!(run.case.scene, draw::CaseScene::Builtin(_))
    );
    reproduces(&run, out.path());
}

/// The same for a case with its scene in external memory: the command carries the caches and
/// the memory model's timing, and `fxrt sim` runs the frame in the same clocks.
#[test]
fn a_reproducer_of_an_external_memory_case_runs_the_same_frame() {
    let out = tempfile::tempdir().unwrap();
    let run = (0..60)
        .filter(|&i| draw::case(5, i, &[]).memory.is_some())
        .map(|i| exact::run_case(5, i, &[], None))
        .find(|r| matches!(r.verdict, Verdict::Ran(_)))
        .expect("an external-memory case of seed 5 that runs");
    let command = reproduces(&run, out.path());
    assert!(command.contains("--memory external") && command.contains("--mem-latency"), "{command}");
}

/// The same for a case whose products are cut for the DSP48E (`--dsp 25x18`) at widths where
/// that shrinks the plane product (n + 1 by m + C bits): the command builds that core, whose
/// ring is shorter than the 18 × 18 cut's, and `fxrt sim` runs the frame in the same clocks.
#[test]
fn a_reproducer_of_a_dsp48_case_builds_the_same_core() {
    use fxrt::cores::mul::{Piece, pieces};
    use fxrt::rtl::Ty;
    let out = tempfile::tempdir().unwrap();
    let shrinks = |c: &draw::Case| {
        let (delta, inv) = (Ty::s(c.params.n + 1), Ty::s(c.params.m + c.params.c));
        pieces(delta, inv, Piece::Dsp48) < pieces(delta, inv, Piece::Mult18)
    };
    let run = (0..200)
        .map(|i| draw::case(5, i, &[]))
        .filter(|c| c.shape.piece == Piece::Dsp48 && c.memory.is_none() && shrinks(c))
        .map(|c| exact::run_case(5, c.index, &[], None))
        .find(|r| matches!(r.verdict, Verdict::Ran(_)))
        .expect("a DSP48E case of seed 5 that runs");
    let command = reproduces(&run, out.path());
    assert!(command.contains("--dsp 25x18"), "{command}");
}

/// Writes `run` out under `out`, checks the scene reads back and the command gives the same
/// frame; returns the command.
fn reproduces(run: &exact::CaseRun, out: &std::path::Path) -> String {
    let Verdict::Ran(outcome) = &run.verdict else { unreachable!() };
    let dir = repro::write(out, run).unwrap();
    let back = fxrt::scene::obj::load_obj(&dir.join("scene.obj")).unwrap();
    assert_eq!(Some(back), run.tris);
    let command = std::fs::read_to_string(dir.join("command.txt")).unwrap();
    let args: Vec<&str> = command.split_whitespace().collect();
    assert_eq!(args[..2], ["fxrt", "sim"]);
    let o = Command::new(env!("CARGO_BIN_EXE_fxrt")).args(&args[1..]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let line: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(line["rays"], outcome.rays);
    assert_eq!(line["cycles"], outcome.cycles);
    assert_eq!(line["walk_matches"], true);
    let steps = line["node_steps_per_ray"].as_f64().unwrap() * outcome.rays as f64;
    assert!((steps - outcome.core_walk.0 as f64).abs() < 0.01 * outcome.rays as f64);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("case.json")).unwrap()).unwrap();
    assert_eq!(json["command"], command.trim_end());
    command
}

/// A case also run in Verilator (`--hdl verilator`): the HDL gives the Rust simulator's results
/// in the same order and in the same cycles, and its testbench checks each against the golden
/// model. (Verilator first refused the n = 40 pipeline's 71-deep tag line this way.)
#[test]
fn a_case_runs_in_verilator_as_in_the_rust_simulator() {
    if !fxrt::verify::simulators::Simulator::Verilator.available() {
        common::say("skipped: verilator is not installed");
        return;
    }
    let run = exact::run_case(3, 0, &[], Some(fxrt::verify::simulators::Simulator::Verilator));
    let Verdict::Ran(o) = &run.verdict else { panic!("case 0 of seed 3 runs: {:?}", run.verdict) };
    assert_eq!(o.hdl, Some(fxrt::verify::simulators::Simulator::Verilator));
    assert!(o.agrees() && o.rays > 0, "{o:?}");
}
