//! A disagreement as a self-contained reproducer: `scene.obj` (the case's triangles, in their
//! order, every coordinate written so it reads back to the same f64), `case.json` (the
//! parameters, shape, camera, feed, the rays that differ with both answers, and the walk
//! totals) and `command.txt`, the `fxrt sim` line that runs the same frame through the same
//! core again — no campaign, no generator, no seed needed.

use super::draw::Case;
use super::{CaseRun, Verdict};
use crate::error::{Error, Result};
use crate::params::TreeSplit;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The triangles as OBJ text: three `v` lines and one `f` line each, in order (Rust prints an
/// f64 as the shortest decimal that parses back to it).
pub fn obj_text(tris: &[crate::scene::Tri]) -> String {
    let mut s = String::from("# fxrt bench exact: a case's scene, triangle k = face k\n");
    for t in tris {
        for v in t {
            writeln!(s, "v {} {} {}", v[0], v[1], v[2]).expect("a String");
        }
    }
    for k in 0..tris.len() {
        writeln!(s, "f {} {} {}", 3 * k + 1, 3 * k + 2, 3 * k + 3).expect("a String");
    }
    s
}

/// The `fxrt sim` arguments that run `case` on `obj` (in `hdl`, when given).
pub fn sim_command(case: &Case, obj: &Path, hdl: Option<crate::verify::simulators::Simulator>) -> String {
    let p = &case.params;
    let s = &case.shape;
    let v = |x: [f64; 3]| format!("{},{},{}", x[0], x[1], x[2]);
    let tree = match p.tree {
        TreeSplit::Sah => "sah",
        TreeSplit::Middle => "middle",
    };
    let mut cmd = format!(
        "fxrt sim {} --n {} --m {} --t {} --c {} --edge-shift {} --leaf-size {} --stack-depth {} --tree {tree} \
         --slots {} --units {} --target-mhz {} --div-bits {}",
        obj.display(),
        p.n,
        p.m,
        p.t,
        p.c,
        p.edge_shift,
        p.leaf_size,
        p.stack_depth,
        s.slots,
        s.units,
        s.target_mhz,
        s.div_bits,
    );
    if p.sah_step_percent > 0 {
        write!(cmd, " --sah-step-percent {}", p.sah_step_percent).expect("a String");
    }
    if s.pipelines > 1 {
        write!(cmd, " --pipelines {}", s.pipelines).expect("a String");
    }
    if s.piece == crate::cores::mul::Piece::Dsp48 {
        cmd.push_str(" --dsp 25x18");
    }
    // A case that panicked before its camera was drawn has none: the panic needs no rays.
    if let Some(cam) = case.camera {
        let size = format!("{}x{}", cam.width, cam.height);
        write!(cmd, " --eye {} --at {} --up {} --fov {} --size {size}", v(cam.eye), v(cam.at), v(cam.up), cam.fov_deg)
            .expect("a String");
    }
    if let Some(sim) = hdl {
        write!(cmd, " --sim {}", sim.name()).expect("a String");
    }
    if let Some(seed) = case.shuffle_seed {
        write!(cmd, " --shuffle-seed {seed}").expect("a String");
    }
    if let Some((percent, seed)) = case.stalls {
        write!(cmd, " --stall-percent {percent} --stall-seed {seed}").expect("a String");
    }
    if let Some((m, t)) = case.memory {
        write!(
            cmd,
            " --memory external --mem-bits {} --cache-line {} --node-cache-kb {} --tri-cache-kb {} --cache-ways {} \
             --mem-latency {} --mem-outstanding {} --mem-jitter {} --mem-pauses {} --mem-seed {}",
            m.shape.mem_bits,
            m.shape.line_bytes,
            m.node_cache_kb,
            m.tri_cache_kb,
            m.ways,
            t.latency,
            t.outstanding,
            t.extra_delay,
            t.pause_in_256,
            t.seed
        )
        .expect("a String");
    }
    cmd
}

/// Writes `OUT/case-<index>/` and returns it. The OBJ is read back before anything is written:
/// a reproducer whose scene would not come back bit for bit is an error, not a file.
pub fn write(out: &Path, run: &CaseRun) -> Result<PathBuf> {
    let case = &run.case;
    let dir = out.join(format!("case-{}", case.index));
    let obj_path = dir.join("scene.obj");
    let tris = run.tris.as_deref().unwrap_or_default();
    let obj = obj_text(tris);
    let check = tempfile::Builder::new().suffix(".obj").tempfile().map_err(|e| Error::file(out, e.to_string()))?;
    std::fs::write(check.path(), &obj).map_err(|e| Error::file(check.path(), e.to_string()))?;
    if !tris.is_empty() && crate::scene::obj::load_obj(check.path())? != tris {
        return Err(Error::file(&obj_path, "the scene does not read back bit for bit as OBJ"));
    }
    // A frame that disagreed only in the HDL simulator is reproduced there.
    let hdl = match &run.verdict {
        Verdict::Ran(o) if o.hdl_disagreement.is_some() && o.disagreeing_rays == 0 && o.core_walk == o.golden_walk => {
            o.hdl
        }
        _ => None,
    };
    let command = sim_command(case, &obj_path, hdl);
    let mut json = serde_json::json!({
        "case": case.index,
        "scene": case.scene.label(),
        "params": case.params,
        "slots": case.shape.slots, "units": case.shape.units, "pipelines": case.shape.pipelines,
        "target_mhz": case.shape.target_mhz, "div_bits": case.shape.div_bits, "dsp": case.shape.piece.label(),
        "camera": case.camera.map(|c| serde_json::json!({
            "eye": c.eye, "at": c.at, "up": c.up, "fov": c.fov_deg, "size": [c.width, c.height], "inside": case.inside })),
        "shuffle_seed": case.shuffle_seed, "stalls": case.stalls,
        "memory": case.memory.map(|(m, t)| serde_json::json!({
            "mem_bits": m.shape.mem_bits, "line_bytes": m.shape.line_bytes, "node_cache_kb": m.node_cache_kb,
            "tri_cache_kb": m.tri_cache_kb, "ways": m.ways, "latency": t.latency, "outstanding": t.outstanding,
            "jitter": t.extra_delay, "pauses_in_256": t.pause_in_256, "seed": t.seed })),
        "command": command,
    });
    match &run.verdict {
        Verdict::Ran(o) => {
            json["rays"] = o.rays.into();
            json["disagreeing_rays"] = o.disagreeing_rays.into();
            json["stray_results"] = o.stray_results.into();
            json["node_steps_and_triangle_tests"] =
                serde_json::json!({ "core": o.core_walk, "golden_culled_walk": o.golden_walk });
            json["disagreements"] = serde_json::to_value(&o.disagreements).expect("serialisable");
            json["hdl"] = o.hdl.map(|s| s.name()).into();
            json["hdl_disagreement"] = o.hdl_disagreement.clone().into();
        }
        Verdict::Panicked(message) => json["panic"] = message.clone().into(),
        Verdict::Refused(e) => json["refused"] = e.to_string().into(),
    }
    let text = serde_json::to_string_pretty(&json).expect("serialisable") + "\n";
    let mut out = crate::io::OutputSet::new();
    out.add(&obj_path, obj.as_bytes())?;
    out.add(&dir.join("case.json"), text.as_bytes())?;
    out.add(&dir.join("command.txt"), format!("{command}\n").as_bytes())?;
    out.commit()?;
    Ok(dir)
}
