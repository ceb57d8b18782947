//! `fxrt gen`: the cores' HDL, their JSON manifests, and the ISE project files.

use crate::cores::intersect::{IntersectParams, intersect_core};
use crate::cores::top::{CoreParams, core_module_with, core_with_raygen};
use crate::model::raygen::RayGen;
use crate::rtl::emit;
use crate::rtl::netlist::Module;
use crate::scene::images::SceneRoms;
use askama::Template;
use serde_json::{Value, json};

/// The JSON manifest written beside a core's HDL. `latency` is None for the whole core, whose
/// results come after a number of cycles that depends on the ray.
pub fn manifest(m: &Module, latency: Option<u32>, params: Value) -> Value {
    let port = |name: &str, dir: &str, ty: crate::rtl::Ty| json!({ "name": name, "direction": dir, "width": ty.width, "signed": ty.signed });
    let mut ports = vec![json!({ "name": "clk", "direction": "in", "width": 1, "signed": false })];
    if m.has_reset() {
        ports.push(json!({ "name": "rst", "direction": "in", "width": 1, "signed": false }));
    }
    ports.extend(m.inputs.iter().map(|&i| port(&m.sig(i).name, "in", m.sig(i).ty)));
    ports.extend(m.outputs.iter().map(|(n, i)| port(n, "out", m.sig(*i).ty)));
    let names = |ext: &str| m.hierarchy().iter().map(|x| format!("{}.{ext}", x.name)).collect::<Vec<_>>();
    json!({
        "name": m.name,
        "generator": format!("fxrt {}", env!("CARGO_PKG_VERSION")),
        "latency_cycles": latency,
        "params": params,
        "ports": ports,
        "register_bits": m.register_bits(),
        "files": { "vhdl": names("vhd"), "verilog": names("v") },
    })
}

/// The intersection pipeline and its divider for one parameter set: (module, latency,
/// manifest parameters).
pub fn cores(p: &IntersectParams) -> Vec<(Module, Option<u32>, Value)> {
    let ip = intersect_core(p);
    let div = p.divider();
    vec![
        (ip, Some(p.latency()), serde_json::to_value(p).unwrap_or(Value::Null)),
        (
            div,
            Some(p.div_latency()),
            json!({ "n": p.n, "bits_per_stage": p.div_bits, "num_width": p.num_width() - p.t, "den_width": p.den_width() - p.t }),
        ),
    ]
}

/// What `fxrt gen` writes besides the HDL.
#[derive(Clone, Copy, Debug)]
pub struct GenOptions {
    pub vhdl: bool,
    pub verilog: bool,
    /// ISE project script and UCF for the XC5VLX110T.
    pub ise: bool,
    /// The core's observation ports too (`core_module_with`).
    pub debug_ports: bool,
    pub clock_mhz: f64,
}

#[derive(Template)]
#[template(path = "ise_project.tcl", escape = "none")]
struct IseProject<'a> {
    top: &'a str,
    scene: &'a str,
    language: &'a str,
    files: &'a [String],
}

#[derive(Template)]
#[template(path = "board.ucf", escape = "none")]
struct BoardUcf<'a> {
    top: &'a str,
    period_ns: String,
}

/// (file name, contents) of every module of `cores` in the chosen languages (each module
/// once), a manifest per core, and the ISE files for the first core when asked.
fn write_set(cores: &[(Module, Option<u32>, Value)], o: GenOptions, scene: &str) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    for (m, lat, params) in cores {
        for ext in [("vhd", o.vhdl), ("v", o.verilog)].iter().filter(|e| e.1).map(|e| e.0) {
            for (name, text) in emit::design_files(m, ext) {
                if !out.iter().any(|(n, _)| *n == name) {
                    out.push((name, text));
                }
            }
        }
        let text = serde_json::to_string_pretty(&manifest(m, *lat, params.clone())).unwrap_or_default() + "\n";
        out.push((format!("{}.json", m.name), text));
    }
    if let (true, Some((top, _, _))) = (o.ise, cores.first()) {
        let (language, ext) = if o.vhdl { ("VHDL", "vhd") } else { ("Verilog", "v") };
        let files: Vec<String> = top.hierarchy().iter().map(|x| format!("{}.{ext}", x.name)).collect();
        let tcl = IseProject { top: &top.name, scene, language, files: &files }.render().expect("ISE template renders");
        out.push((format!("{}.tcl", top.name), tcl + "\n"));
        let period_ns = format!("{:.3}", 1000.0 / o.clock_mhz);
        let ucf = BoardUcf { top: &top.name, period_ns }.render().expect("UCF template renders");
        out.push((format!("{}.ucf", top.name), ucf + "\n"));
    }
    out
}

/// The pipeline cores alone (intersection pipeline and divider).
pub fn files(p: &IntersectParams, vhdl: bool, verilog: bool) -> Vec<(String, String)> {
    write_set(&cores(p), GenOptions { vhdl, verilog, ise: false, debug_ports: false, clock_mhz: p.target_mhz as f64 }, "")
}

/// The whole ray tracing core for a scene (fed by the on-chip ray generator when `raygen` is
/// given), with manifests for it and for each of its cores.
pub fn core_files(p: &CoreParams, roms: &SceneRoms, o: GenOptions, raygen: Option<&RayGen>) -> Vec<(String, String)> {
    let top = match raygen {
        Some(g) => core_with_raygen(p, roms, g, o.debug_ports),
        None => core_module_with(p, roms, o.debug_ports),
    };
    let core_params = json!({
        "scene": roms.name,
        "triangles": roms.tri_count(),
        "n": p.isect.n, "m": p.isect.m, "t": p.isect.t, "c": p.trav.c, "e": p.isect.e,
        "stack_depth": p.trav.stack_depth, "ray_id_width": p.trav.id_width, "div_bits": p.isect.div_bits, "target_mhz": p.isect.target_mhz,
        "intersection_latency_cycles": p.isect.latency(),
        "leaf_entry_to_result_cycles": p.stream_latency() + 1,
        "ray_slots_per_unit": p.trav.slots, "traversal_units": p.units,
        "results_in_order": false,
        "result_order": "rays finish out of order; every result carries its ray id (res_id)",
    });
    let mut set = vec![(top, None, core_params)];
    set.extend(cores(&p.isect));
    write_set(&set, o, &roms.name)
}
